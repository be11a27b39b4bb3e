#include "lesson/lesson_check.h"

#include <fnmatch.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <regex>
#include <sstream>

#include "core/error.h"
#include "core/paths.h"
#include "graph/technique.h"

namespace voxlab {
namespace {

namespace fs = std::filesystem;

// Folders of the repository a lesson may point a student to.
const char* const kRepositoryFolders[] = {"src/", "shaders/", "lessons/", "docs/", "scenes/", "tests/", "scripts/"};

// Does 'relative' (possibly with '*' inside its last name, or a trailing '/') exist under 'root'?
bool repositoryPathExists(const fs::path& root, std::string relative) {
  while (!relative.empty() && relative.back() == '/') relative.pop_back();
  if (relative.find('*') == std::string::npos) return fs::exists(root / relative);
  const fs::path p(relative);
  const fs::path dir = root / p.parent_path();
  if (!fs::is_directory(dir)) return false;
  const std::string pattern = p.filename().string();
  for (const auto& e : fs::directory_iterator(dir))
    if (fnmatch(pattern.c_str(), e.path().filename().string().c_str(), 0) == 0) return true;
  return false;
}

struct TextLine {
  int number;        // 1-based line of the file
  std::string text;
  int section;       // index of the step whose narrative holds it; steps.size() for the epilogue
  bool code;         // inside a fenced block (step blocks included)
};

std::vector<TextLine> narrativeLines(const std::string& text) {
  std::vector<TextLine> lines;
  std::istringstream in(text);
  std::string line;
  int number = 0, section = 0;
  bool inStep = false, inFence = false;
  while (std::getline(in, line)) {
    ++number;
    std::string t = line.substr(std::min(line.find_first_not_of(" \t"), line.size()));
    const bool fence = t.rfind("```", 0) == 0;
    if (inStep) {
      lines.push_back({number, line, section, true});
      if (fence) {
        inStep = false;
        ++section;
      }
      continue;
    }
    if (fence && !inFence && t.rfind("```voxlab-step", 0) == 0) {
      inStep = true;
      lines.push_back({number, line, section, true});
      continue;
    }
    if (fence) {
      inFence = !inFence;
      lines.push_back({number, line, section, true});
      continue;
    }
    lines.push_back({number, line, section, inFence});
  }
  return lines;
}

// Text outside inline code spans (`...`), so that "step 3" inside a command is not read as prose.
std::string withoutCodeSpans(const std::string& line) {
  std::string out;
  bool code = false;
  for (char c : line) {
    if (c == '`') {
      code = !code;
      out += ' ';
    } else if (!code) {
      out += c;
    }
  }
  return out;
}

class TextChecker {
 public:
  TextChecker(const Lesson& lesson, const std::string& text) : lesson_(lesson), lines_(narrativeLines(text)) {
    ids_ = techniqueIds();
  }

  std::vector<std::string> run() {
    checkHeadings();
    for (const TextLine& l : lines_) {
      if (l.code) continue;
      checkStepReferences(l);
      checkCodeSpans(l);
      checkLinks(l);
      checkKeys(l);
      checkSourceNumbering(l);
    }
    return problems_;
  }

 private:
  void problem(int line, const std::string& what) {
    problems_.push_back(lesson_.path + ":" + std::to_string(line) + ": " + what);
  }

  int stepCount() const { return int(lesson_.steps.size()); }

  void checkHeadings() {
    static const std::regex heading(R"(^##\s+Step\s+([^:\s]+)\s*:)");
    std::vector<int> found(lesson_.steps.size(), 0);
    for (const TextLine& l : lines_) {
      std::smatch m;
      if (l.code || !std::regex_search(l.text, m, heading)) continue;
      if (l.section >= stepCount()) {
        problem(l.number, "heading \"" + l.text + "\" comes after the last step block; every \"## Step N:\" "
                          "heading opens the narrative of step N, so it needs a voxlab-step block after it");
        continue;
      }
      const std::string want = std::to_string(l.section + 1);
      if (m[1].str() != want)
        problem(l.number, "heading \"Step " + m[1].str() + "\" is step " + want + " of " + std::to_string(stepCount()) +
                              " (the viewer's counter and its number keys count step blocks); write \"## Step " +
                              want + ":\" and renumber the headings after it");
      if (++found[l.section] == 2)
        problem(l.number, "step " + want + " has a second \"## Step\" heading; give each step its own voxlab-step block");
    }
    for (int s = 0; s < stepCount(); ++s)
      if (found[s] == 0)
        problem(lesson_.steps[s].line, "step " + std::to_string(s + 1) + " has no \"## Step " + std::to_string(s + 1) +
                                           ": title\" heading in its narrative (the text before its voxlab-step block)");
  }

  void checkStepReferences(const TextLine& l) {
    static const std::regex heading(R"(^##\s+Step\s)");
    if (std::regex_search(l.text, heading)) return;
    static const std::regex ref(R"(\b[Ss]teps?\s+(\d+)(?:\s*(?:-|to|and|or)\s*(\d+))?)");
    const std::string prose = withoutCodeSpans(l.text);
    // "lesson 01, step 15" names another lesson's step: not this one's.
    static const std::regex otherLesson(R"([Ll]esson\s+\d+(?:'s|,)?\s*$)");
    for (std::sregex_iterator it(prose.begin(), prose.end(), ref), end; it != end; ++it) {
      const size_t at = size_t(it->position());
      const std::string before = prose.substr(at > 20 ? at - 20 : 0, at > 20 ? 20 : at);
      if (std::regex_search(before, otherLesson)) continue;
      for (int g = 1; g <= 2; ++g) {
        if (!(*it)[g].matched) continue;
        int k = std::stoi((*it)[g].str());
        if (k < 1 || k > stepCount())
          problem(l.number, "\"" + it->str() + "\" names step " + std::to_string(k) + ", but the lesson has steps 1.." +
                                std::to_string(stepCount()));
      }
    }
  }

  const LessonStep& stepOf(const TextLine& l) const {
    return lesson_.steps[std::min<size_t>(size_t(l.section), lesson_.steps.size() - 1)];
  }

  void checkCodeSpans(const TextLine& l) {
    static const std::regex span("`([^`]+)`");
    static const std::regex address(R"(^([a-z0-9-]+)/([a-z0-9-]+)(?:/([a-z0-9-]+))?(?:@\d+)?$)");
    for (std::sregex_iterator it(l.text.begin(), l.text.end(), span), end; it != end; ++it) {
      const std::string token = (*it)[1].str();
      if (token.find(' ') != std::string::npos) continue;
      bool repositoryPath = false;
      for (const char* folder : kRepositoryFolders) repositoryPath = repositoryPath || token.rfind(folder, 0) == 0;
      if (repositoryPath) {
        if (!repositoryPathExists(fs::path(projectRoot()), token))
          problem(l.number, "`" + token + "` is not in the repository; name a file or folder that exists");
        continue;
      }
      std::smatch m;
      if (std::regex_match(token, m, address)) checkAddress(l, token, m);
    }
  }

  void checkAddress(const TextLine& l, const std::string& token, const std::smatch& m) {
    std::string technique, stage, output;
    if (m[3].matched) {
      if (std::find(ids_.begin(), ids_.end(), m[1].str()) == ids_.end()) return;
      technique = m[1].str(), stage = m[2].str(), output = m[3].str();
    } else {
      technique = stepOf(l).technique, stage = m[1].str(), output = m[2].str();
    }
    const Technique& t = technique_(technique);
    const auto stages = t.stageIds();
    if (std::find(stages.begin(), stages.end(), stage) == stages.end()) {
      if (m[3].matched) problem(l.number, "`" + token + "`: " + technique + " has no stage " + stage);
      return;  // "a/b" that is not stage/output (a ratio, a path fragment)
    }
    try {
      t.findOutput(stage, output);
    } catch (const Error& e) {
      problem(l.number, "`" + token + "`: " + e.what());
    }
  }

  const Technique& technique_(const std::string& id) {
    auto& slot = techniques_[id];
    if (!slot) slot = createTechnique(id);
    return *slot;
  }

  // Markdown links and bare relative paths ("../docs/x.md") resolve against the lesson's folder and
  // must stay inside the repository: a student has the repository, not the machine it was written on.
  void checkLinks(const TextLine& l) {
    static const std::regex link(R"(\]\(([^)\s]+)\))");
    static const std::regex bare(R"((?:^|[\s(])(\.\./[A-Za-z0-9_./-]*[A-Za-z0-9_/]))");
    const fs::path folder = fs::path(lesson_.path).parent_path();
    std::vector<std::string> targets;
    for (std::sregex_iterator it(l.text.begin(), l.text.end(), link), end; it != end; ++it) targets.push_back((*it)[1].str());
    const std::string prose = withoutCodeSpans(std::regex_replace(l.text, link, "]"));
    for (std::sregex_iterator it(prose.begin(), prose.end(), bare), end; it != end; ++it) targets.push_back((*it)[1].str());
    const fs::path root = fs::weakly_canonical(fs::path(projectRoot()));
    for (std::string target : targets) {
      if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0 || target[0] == '#') continue;
      target = target.substr(0, target.find('#'));
      const fs::path resolved = fs::weakly_canonical(folder / target);
      const std::string inside = fs::relative(resolved, root).string();
      if (inside.empty() || inside.rfind("..", 0) == 0)
        problem(l.number, target + " lies outside the repository; point to a file in it (docs/, src/, ...)");
      else if (!fs::exists(resolved))
        problem(l.number, "link target " + target + " does not exist (links resolve against the lesson's folder)");
    }
  }

  void checkKeys(const TextLine& l) {
    // Key names as a lesson writes them: a single capital or digit, F1-F12, Page Up/Down or a
    // named key; ordinary words after "key" ("the key trick") are not read as keys.
    static const std::regex key(
        R"(\b(?:[Kk]ey|[Pp]ress)\s+(Page\s+(?:Up|Down)|F\d+|[A-Z0-9](?![A-Za-z0-9])|)"
        R"((?:Escape|Space|Backspace|Home|End|Left|Right|Shift|Ctrl|Enter|Return|Tab|Delete|Insert)\b))");
    const std::string prose = withoutCodeSpans(l.text);
    const auto& known = viewerKeyNames();
    for (std::sregex_iterator it(prose.begin(), prose.end(), key), end; it != end; ++it) {
      std::string name = std::regex_replace((*it)[1].str(), std::regex(R"(\s+)"), " ");
      if (std::find(known.begin(), known.end(), name) != known.end()) continue;
      std::string valid;
      for (const auto& k : known) valid += (valid.empty() ? "" : ", ") + k;
      problem(l.number, "\"" + it->str() + "\": the viewer has no key " + name + "; its keys: " + valid);
    }
  }

  void checkSourceNumbering(const TextLine& l) {
    static const std::regex seed(R"(\b[Ss]eeds?\b)");
    if (std::regex_search(withoutCodeSpans(l.text), seed))
      problem(l.number, "\"seed\" is the project's own numbering of its sources and means nothing to a student; cite "
                        "the paper or thesis by author, year and section");
  }

  const Lesson& lesson_;
  std::vector<TextLine> lines_;
  std::vector<std::string> ids_;
  std::map<std::string, std::unique_ptr<Technique>> techniques_;
  std::vector<std::string> problems_;
};

}  // namespace

const std::vector<std::string>& viewerKeyNames() {
  // The keys src/inspect/viewer.cpp and panel_presenter.cpp handle (a test checks the letters and
  // function keys against those files).
  static const std::vector<std::string> keys = {
      "I", "R", "A", "W", "S", "D", "Q", "E", "P", "F5", "F11", "Escape", "Space", "Backspace", "Home", "End",
      "Page Up", "Page Down", "Left", "Right", "Shift", "Ctrl", "0", "1", "2", "3", "4", "5", "6", "7", "8", "9"};
  return keys;
}

std::vector<std::string> lessonTextProblems(const Lesson& lesson, const std::string& text) {
  if (lesson.steps.empty()) return {};
  return TextChecker(lesson, text).run();
}

double pictureDetail(const DisplayImage& image) {
  const size_t n = size_t(image.width) * image.height;
  if (n == 0) return 0.0;
  std::map<int, size_t> counts;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = &image.rgb[i * 3];
    ++counts[(p[0] >> 4) << 8 | (p[1] >> 4) << 4 | (p[2] >> 4)];
  }
  const int mode = std::max_element(counts.begin(), counts.end(), [](const auto& a, const auto& b) {
                     return a.second < b.second;
                   })->first;
  std::array<double, 3> mean{0, 0, 0};
  size_t inMode = 0;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = &image.rgb[i * 3];
    if (((p[0] >> 4) << 8 | (p[1] >> 4) << 4 | (p[2] >> 4)) != mode) continue;
    for (int c = 0; c < 3; ++c) mean[c] += p[c];
    ++inMode;
  }
  for (double& m : mean) m /= double(inMode);
  size_t standOut = 0;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = &image.rgb[i * 3];
    bool differs = false;
    for (int c = 0; c < 3; ++c) differs = differs || std::abs(double(p[c]) - mean[c]) > 12.0;
    standOut += differs;
  }
  return double(standOut) / double(n);
}

}  // namespace voxlab
