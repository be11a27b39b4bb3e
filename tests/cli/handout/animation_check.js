// Appended to a handout page by browser_check.sh: after the load event, decodes every animated
// step picture (img.animation) with the browser's own image decoder (WebCodecs ImageDecoder) and
// writes <pre id="voxlab-anim">animations=A playing=P</pre>, P counting the images the browser
// decodes as an animation of two frames or more whose first and last frames differ in some pixel
// (what a reader sees move when the image plays).
window.addEventListener("load", function () {
  var out = document.createElement("pre");
  out.id = "voxlab-anim";
  var images = Array.prototype.slice.call(document.querySelectorAll("img.animation"));
  function pixels(frame) {
    var canvas = document.createElement("canvas");
    canvas.width = frame.displayWidth;
    canvas.height = frame.displayHeight;
    var context = canvas.getContext("2d");
    context.drawImage(frame, 0, 0);
    return context.getImageData(0, 0, canvas.width, canvas.height).data;
  }
  function plays(img) {
    return new Promise(function (resolve) {
      var xhr = new XMLHttpRequest();
      xhr.open("GET", img.src);
      xhr.responseType = "arraybuffer";
      xhr.onerror = function () { resolve(false); };
      xhr.onload = function () {
        if (typeof ImageDecoder === "undefined") { resolve(false); return; }
        var decoder = new ImageDecoder({data: xhr.response, type: "image/png"});
        decoder.tracks.ready.then(function () {
          var track = decoder.tracks.selectedTrack;
          if (!track.animated || track.frameCount < 2) return false;
          return Promise.all([decoder.decode({frameIndex: 0}), decoder.decode({frameIndex: track.frameCount - 1})])
            .then(function (r) {
              var a = pixels(r[0].image), b = pixels(r[1].image);
              for (var i = 0; i < a.length; ++i) if (a[i] !== b[i]) return true;
              return false;
            });
        }).then(resolve, function () { resolve(false); });
      };
      xhr.send();
    });
  }
  Promise.all(images.map(plays)).then(function (results) {
    out.textContent = "animations=" + images.length + " playing=" + results.filter(function (p) { return p; }).length;
    document.body.appendChild(out);
  });
});
