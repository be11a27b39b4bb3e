#include "inspect/figure.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "capture/image_files.h"
#include "capture/output_handler.h"
#include "core/error.h"
#include "core/html.h"
#include "graph/reference_mode.h"
#include "run/reference_error.h"

namespace voxlab {
namespace {

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string base64(const std::string& bytes) {
  static const char* const kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const uint32_t a = uint8_t(bytes[i]), b = i + 1 < bytes.size() ? uint8_t(bytes[i + 1]) : 0,
                   c = i + 2 < bytes.size() ? uint8_t(bytes[i + 2]) : 0, v = (a << 16) | (b << 8) | c;
    out += kDigits[(v >> 18) & 63];
    out += kDigits[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[v & 63] : '=';
  }
  return out;
}

std::string pngDataUri(const DisplayImage& image) {
  return "data:image/png;base64," + base64(encodePng(image.width, image.height, 3, image.rgb.data()));
}


}  // namespace

Figure outputFigure(StepCursor& cursor, const FigureRequest& request) {
  const Technique& t = cursor.technique();
  const auto [stage, desc] = t.findOutput(request.stage, request.output);  // unknown: one line listing the valid ones
  (void)stage;
  CapturedOutput cap = captureOutput(cursor.board(), *desc);
  const std::string address = t.id() + "/" + request.stage + "/" + request.output;
  Figure figure;
  FigureImage shown;
  if (desc->kind == OutputKind::Buffer) {
    if (recordPoints(cap).empty())
      throw Error("output " + address + " is a buffer without a position field; a figure shows images, volumes and "
                  "point buffers");
    shown.image = pointView(cap, std::max(cursor.view().width, cursor.view().height));
    figure.title = address;
  } else {
    if (request.level < 0 || request.level >= int(cap.levels.size()))
      throw Error("output " + address + " has levels 0.." + std::to_string(int(cap.levels.size()) - 1) + ", not " +
                  std::to_string(request.level));
    const LevelData& level = cap.levels[size_t(request.level)];
    const SliceSpec slice = sliceToShow(level, request.slice);
    shown.image = rgbOf(mapSlice(level, desc->semantic, slice, request.display));
    figure.title = address + "@" + std::to_string(request.level);
    if (desc->kind == OutputKind::Volume3D)
      figure.title += ", slice " + std::string(1, char('x' + slice.axis)) + " = " +
                      std::to_string(std::clamp(slice.index, 0, level.size[slice.axis] - 1));
    const int channel = request.display.channel >= level.channels ? level.channels - 1 : request.display.channel;
    if (texelMapping(desc->semantic).normalise && level.channels > 0) {
      ColourBar bar;
      normalisedRange(level, std::max(channel, 0), bar.lo, bar.hi);
      bar.label = semanticName(desc->semantic) + (level.channels > 1 ? ", channel " + std::to_string(std::max(channel, 0)) : "");
      figure.colourBar = bar;
    }
  }
  shown.caption = request.output;
  figure.images.push_back(shown);

  const std::string scene = cursor.scene().name;
  figure.notes.push_back(t.title() + " on " + scene + ", " + std::to_string(cursor.view().width) + "x" +
                         std::to_string(cursor.view().height) +
                         (request.display.exposure != 1.0f ? ", exposure " + fmt("%g", request.display.exposure) : ""));
  const auto defaults = t.defaultParams().formatted(), now = cursor.params().formatted();
  std::string changed;
  for (const auto& [name, value] : now)
    if (defaults.count(name) && defaults.at(name) != value) changed += (changed.empty() ? "" : ", ") + name + "=" + value;
  figure.notes.push_back(changed.empty() ? "parameters: the technique's defaults" : "parameters: " + changed);

  if (request.withReference && !desc->referenceMode.empty() && desc->kind == OutputKind::Image2D) {
    const std::string mode = referenceModeUnder(*desc, cursor.params());
    const std::string path = referenceImagePath(scene, mode);
    if (std::filesystem::exists(path)) figure.images.push_back({referenceDisplayImage(*desc, path), "reference (" + mode + ")"});
  }
  return figure;
}

std::string figureSvg(const Figure& figure, int width) {
  width = std::max(width, 64);
  const double margin = 12, gap = 10, titleHeight = 22, noteHeight = 16, captionHeight = 18;
  const double barHeight = figure.colourBar ? 46 : 0;
  const size_t n = std::max<size_t>(figure.images.size(), 1);
  const double cell = (width - 2 * margin - gap * double(n - 1)) / double(n);
  double imageHeight = 0;
  for (const FigureImage& f : figure.images)
    imageHeight = std::max(imageHeight, cell * double(f.image.height) / double(std::max(f.image.width, 1)));
  const double top = margin + titleHeight + noteHeight * double(figure.notes.size()) + 6;
  const double height = top + imageHeight + captionHeight + barHeight + margin;
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(width) + "\" height=\"" +
                  fmt("%.0f", height) + "\" viewBox=\"0 0 " + std::to_string(width) + " " + fmt("%.0f", height) +
                  "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s += "<text class=\"title\" x=\"" + fmt("%.1f", margin) + "\" y=\"" + fmt("%.1f", margin + 15) +
       "\" font-size=\"15\" font-weight=\"bold\">" + htmlEscape(figure.title) + "</text>\n";
  for (size_t i = 0; i < figure.notes.size(); ++i)
    s += "<text class=\"note\" x=\"" + fmt("%.1f", margin) + "\" y=\"" +
         fmt("%.1f", margin + titleHeight + noteHeight * double(i) + 11) + "\" fill=\"#444\">" +
         htmlEscape(figure.notes[i]) + "</text>\n";
  for (size_t i = 0; i < figure.images.size(); ++i) {
    const FigureImage& f = figure.images[i];
    const double x = margin + double(i) * (cell + gap);
    const double h = cell * double(f.image.height) / double(std::max(f.image.width, 1));
    s += "<image class=\"picture\" x=\"" + fmt("%.1f", x) + "\" y=\"" + fmt("%.1f", top) + "\" width=\"" +
         fmt("%.1f", cell) + "\" height=\"" + fmt("%.1f", h) +
         "\" style=\"image-rendering: pixelated\" preserveAspectRatio=\"none\" href=\"" + pngDataUri(f.image) + "\"/>\n";
    s += "<text class=\"caption\" x=\"" + fmt("%.1f", x + cell / 2) + "\" y=\"" + fmt("%.1f", top + imageHeight + 13) +
         "\" text-anchor=\"middle\">" + htmlEscape(f.caption) + "</text>\n";
  }
  if (figure.colourBar) {
    const ColourBar& bar = *figure.colourBar;
    const double y = top + imageHeight + captionHeight + 4, barWidth = std::min(cell, 320.0);
    s += "<defs><linearGradient id=\"ramp\" x1=\"0\" x2=\"1\" y1=\"0\" y2=\"0\">";
    for (int k = 0; k <= 16; ++k) {
      uint8_t rgb[3];
      falseColourRamp(float(k) / 16.0f, rgb);
      s += "<stop offset=\"" + fmt("%.4f", k / 16.0) + "\" stop-color=\"rgb(" + std::to_string(rgb[0]) + "," +
           std::to_string(rgb[1]) + "," + std::to_string(rgb[2]) + ")\"/>";
    }
    s += "</linearGradient></defs>\n";
    s += "<rect class=\"colour-bar\" x=\"" + fmt("%.1f", margin) + "\" y=\"" + fmt("%.1f", y) + "\" width=\"" +
         fmt("%.1f", barWidth) + "\" height=\"12\" fill=\"url(#ramp)\" stroke=\"#444\"/>\n";
    s += "<text class=\"bar-low\" x=\"" + fmt("%.1f", margin) + "\" y=\"" + fmt("%.1f", y + 26) + "\">" +
         htmlEscape(fmt("%.4g", bar.lo)) + "</text>\n";
    s += "<text class=\"bar-high\" x=\"" + fmt("%.1f", margin + barWidth) + "\" y=\"" + fmt("%.1f", y + 26) +
         "\" text-anchor=\"end\">" + htmlEscape(fmt("%.4g", bar.hi)) + "</text>\n";
    s += "<text class=\"bar-label\" x=\"" + fmt("%.1f", margin + barWidth / 2) + "\" y=\"" + fmt("%.1f", y + 26) +
         "\" text-anchor=\"middle\" fill=\"#444\">" + htmlEscape(bar.label) + "</text>\n";
  }
  s += "</svg>\n";
  return s;
}

}  // namespace voxlab
