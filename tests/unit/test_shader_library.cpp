// ShaderLibrary: #include resolution, errors reported with the original file and line, and hot
// reload that keeps the last good program when an edit breaks it.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include <unistd.h>

#include "gpu/shader_library.h"
#include "platform/gl_context.h"

namespace voxlab {
namespace {

namespace fs = std::filesystem;

class ShaderLibraryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    context_ = createOffscreenContext();
    root_ = fs::temp_directory_path() / ("voxlab-shaders-" + std::to_string(::getpid()));
    fs::create_directories(root_ / "common");
    write("common/helpers.glsl", "// helper\nfloat twice(float x) { return 2.0 * x; }\n");
    write("fill.comp.glsl",
          "#version 450\n#include \"common/helpers.glsl\"\nlayout(local_size_x = 1) in;\n"
          "layout(std430, binding = 0) buffer B { float v[]; };\nvoid main() { v[0] = twice(21.0); }\n");
  }
  void TearDown() override { fs::remove_all(root_); }
  void write(const std::string& name, const std::string& text) {
    // Bump the modification time visibly for the reload check.
    std::ofstream(root_ / name) << text;
    auto t = fs::last_write_time(root_ / name);
    fs::last_write_time(root_ / name, t + std::chrono::seconds(++tick_));
  }
  std::unique_ptr<GLContext> context_;
  fs::path root_;
  int tick_ = 0;
};

TEST_F(ShaderLibraryTest, ResolvesIncludesAndRuns) {
  ShaderLibrary lib(root_.string());
  GLuint p = lib.program({"fill.comp.glsl"});
  ASSERT_NE(p, 0u);
  auto sources = lib.sourcesOf({"fill.comp.glsl"});
  EXPECT_EQ(sources.size(), 2u);  // the stage file and the included helper
  GLuint buf = 0;
  glCreateBuffers(1, &buf);
  float zero = 0;
  glNamedBufferStorage(buf, 4, &zero, GL_DYNAMIC_STORAGE_BIT);
  glUseProgram(p);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buf);
  glDispatchCompute(1, 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  float v = 0;
  glGetNamedBufferSubData(buf, 0, 4, &v);
  glDeleteBuffers(1, &buf);
  EXPECT_EQ(v, 42.0f);
}

TEST_F(ShaderLibraryTest, ErrorsNameTheIncludedFileAndLine) {
  write("common/helpers.glsl", "// helper\nfloat twice(float x) { return 2.0 * y; }\n");
  ShaderLibrary lib(root_.string());
  try {
    lib.program({"fill.comp.glsl"});
    FAIL() << "a broken include compiled";
  } catch (const ShaderError& e) {
    EXPECT_NE(std::string(e.what()).find("common/helpers.glsl:2:"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

TEST_F(ShaderLibraryTest, MissingIncludeNamesTheIncludingLine) {
  write("bad.comp.glsl", "#version 450\nlayout(local_size_x = 1) in;\n#include \"common/nope.glsl\"\nvoid main() {}\n");
  ShaderLibrary lib(root_.string());
  try {
    lib.program({"bad.comp.glsl"});
    FAIL() << "a missing include compiled";
  } catch (const ShaderError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.comp.glsl:3: #include \"common/nope.glsl\" not found"), std::string::npos)
        << e.what();
  }
}

TEST_F(ShaderLibraryTest, FailedReloadKeepsTheLastGoodProgram) {
  ShaderLibrary lib(root_.string());
  GLuint good = lib.program({"fill.comp.glsl"});
  EXPECT_TRUE(lib.reloadChanged().empty());  // nothing changed yet
  EXPECT_EQ(lib.lastReloadCount(), 0);
  write("common/helpers.glsl", "// helper\nfloat twice(float x) { return 2.0 * x }\n");
  auto failures = lib.reloadChanged();
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_NE(failures[0].find("common/helpers.glsl:2:"), std::string::npos) << failures[0];
  EXPECT_EQ(lib.program({"fill.comp.glsl"}), good);
  EXPECT_TRUE(glIsProgram(good));
  write("common/helpers.glsl", "// helper\nfloat twice(float x) { return x + x; }\n");
  EXPECT_TRUE(lib.reloadChanged().empty());
  EXPECT_EQ(lib.lastReloadCount(), 1);  // the viewer's file watch reacts to this
  EXPECT_NE(lib.program({"fill.comp.glsl"}), 0u);
}

}  // namespace
}  // namespace voxlab
