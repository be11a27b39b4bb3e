#!/bin/sh
# Handouts in a real browser: `voxlab handout --all` writes every lesson in lessons/ and the index
# (at 96x96 pictures, to keep the test short; the pictures' size changes nothing in the HTML),
# then headless Chromium opens the index and every handout. A script appended to a copy of
# each page writes, after the load event, how many <img> there are, how many loaded
# (naturalWidth > 0) and how many step sections and index rows the page has; --dump-dom prints the
# resulting DOM. Every image must have loaded, the handout must have as many sections as the
# lesson file has ```voxlab-step blocks, the index one row per lesson. A control page with one
# missing picture must report it (so the check can fail). A step with "frames" adds an animated
# PNG: animation_check.js decodes each with Chromium's own decoder and counts those that play (an
# animation of two frames or more whose first and last frames differ); every one must, and a
# control page whose animation is swapped for a still picture must report it.
# Exit 77 (skip) only when chromium is not installed (scripts/setup.sh installs it).
set -e
exe="$1"; root="$2"; out="$3"
command -v chromium >/dev/null 2>&1 || { echo "chromium is not installed (scripts/setup.sh installs it): skipping"; exit 77; }
rm -rf "$out"; mkdir -p "$out"
"$exe" handout --all --size 96x96 --out "$out/handouts" >"$out/handout.log" 2>&1 || { cat "$out/handout.log"; exit 1; }
cat "$out/handout.log"
cp "$root/tests/cli/handout/animation_check.js" "$out/handouts/"

# The page as the browser sees it, plus the reporting script, next to the original (same relative links).
instrument() {  # page.html -> page.check.html
  sed 's#</body>#<script src="animation_check.js"></script><script>\
window.addEventListener("load", function () {\
  var imgs = Array.prototype.slice.call(document.images);\
  var loaded = imgs.filter(function (i) { return i.complete \&\& i.naturalWidth > 0; }).length;\
  var p = document.createElement("pre"); p.id = "voxlab-check";\
  p.textContent = "images=" + imgs.length + " loaded=" + loaded + " sections=" +\
    document.querySelectorAll("section.step").length + " rows=" + document.querySelectorAll("table.index tr").length;\
  document.body.appendChild(p);\
});\
</script></body>#' "$1" > "${1%.html}.check.html"
}
browse() {  # page.check.html -> the check line and the animation line
  # The animation line is written when the browser's image decoder has finished, which runs outside
  # Chromium's virtual time: on a loaded machine the DOM can be dumped before it (seen once: the
  # motion lesson's page in a full CI run at a load average near 2 per core, which passed the run
  # before). A page dumped without it is loaded again, up to three times; a page that never writes
  # it still fails below.
  local attempt
  for attempt in 1 2 3; do
    chromium --headless --no-sandbox --disable-gpu --disable-dev-shm-usage --user-data-dir="$out/profile" \
      --allow-file-access-from-files --virtual-time-budget=20000 --dump-dom "file://$1" 2>"$out/chromium.log" \
      >"$out/dom.html"
    grep -q '<pre id="voxlab-anim">' "$out/dom.html" && break
  done
  echo "$(sed -n 's#.*<pre id="voxlab-check">\([^<]*\)</pre>.*#\1#p' "$out/dom.html")" \
    "$(sed -n 's#.*<pre id="voxlab-anim">\([^<]*\)</pre>.*#\1#p' "$out/dom.html")"
}
expect() {  # what got want
  if [ "$2" != "$3" ]; then echo "FAIL $1: got '$2', want '$3'"; cat "$out/chromium.log"; exit 1; fi
  echo "ok $1: $2"
}

lessons=$(ls "$root"/lessons/*.md | grep -v '/README\.md$')
count=$(echo "$lessons" | wc -l)
instrument "$out/handouts/index.html"
expect index "$(browse "$out/handouts/index.check.html")" "images=$count loaded=$count sections=0 rows=$count animations=0 playing=0"

# Every handout is checked (each costs about a second of Chromium).
for lesson in $lessons; do
  stem=$(basename "$lesson" .md)
  # The step count from the file itself (its ```voxlab-step fences), not from voxlab's parser.
  steps=$(grep -c '^```voxlab-step' "$lesson")
  [ "$steps" -gt 0 ] || { echo "could not count the steps of $lesson"; exit 1; }
  # The animations from the file too: a step block's "frames" key (one per step at most).
  animations=$(grep -c '"frames"' "$lesson" || true)
  images=$((steps + animations))
  instrument "$out/handouts/$stem.html"
  expect "$stem" "$(browse "$out/handouts/$stem.check.html")" \
    "images=$images loaded=$images sections=$steps rows=0 animations=$animations playing=$animations"
done

first=$(echo "$lessons" | head -n 1)
stem=$(basename "$first" .md)
steps=$(grep -c '^```voxlab-step' "$first")
# Control: the same handout with its second picture missing must report one image not loaded.
sed 's#src="'"$stem"'/step-02.png"#src="'"$stem"'/no-such-picture.png"#' "$out/handouts/$stem.html" > "$out/handouts/control.html"
instrument "$out/handouts/control.html"
expect control "$(browse "$out/handouts/control.check.html")" \
  "images=$steps loaded=$((steps - 1)) sections=$steps rows=0 animations=0 playing=0"
# Control: a handout with animations, the first one swapped for its step's still picture, must
# report one animation that does not play.
animated=$(grep -l '"frames"' $lessons | head -n 1)
if [ -n "$animated" ]; then
  stem=$(basename "$animated" .md)
  steps=$(grep -c '^```voxlab-step' "$animated")
  animations=$(grep -c '"frames"' "$animated")
  first=$(grep -o "$stem/step-[0-9]*-frames.png" "$out/handouts/$stem.html" | head -n 1)
  sed "s#src=\"$first\"#src=\"${first%-frames.png}.png\"#" "$out/handouts/$stem.html" > "$out/handouts/control-animation.html"
  instrument "$out/handouts/control-animation.html"
  expect control-animation "$(browse "$out/handouts/control-animation.check.html")" \
    "images=$((steps + animations)) loaded=$((steps + animations)) sections=$steps rows=0 animations=$animations playing=$((animations - 1))"
fi
echo "handouts load in chromium"
