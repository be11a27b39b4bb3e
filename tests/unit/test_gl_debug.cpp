// GL debug output (gpu/gl_debug.h): a GL error in the current context arrives as a message of
// severity high with the scope it happened in, printed once however often it repeats. The test
// takes the failures itself, so the listener of test_main.cpp (which fails any test leaving
// some) does not fail it.
#include <gtest/gtest.h>

#include "gpu/gl_debug.h"
#include "gpu/resources.h"
#include "test_support.h"

namespace voxlab {
namespace {

TEST(GLDebug, ErrorArrivesWithItsScope) {
  RunRequest r;
  r.technique = techniqueIds().front();
  r.width = r.height = 32;
  testing_support::session(r);  // a current context with debug output installed by loadGL()
  takeGLFailures();
  {
    GLDebugScope stage("stage probe/test");
    TextureDesc d;
    d.size = {8, 8, 1};
    Texture t("deliberately-bad", d);
    GLDebugScope object("texture 'deliberately-bad' misuse");
    for (int i = 0; i < 3; ++i) glTextureStorage2D(t.id(), 1, GL_RGBA8, 8, 8);  // immutable: INVALID_OPERATION
  }
  const std::vector<GLDebugMessage> failures = takeGLFailures();
  ASSERT_EQ(failures.size(), 3u);
  EXPECT_EQ(failures[0].severity, GLenum(GL_DEBUG_SEVERITY_HIGH));
  EXPECT_EQ(failures[0].type, GLenum(GL_DEBUG_TYPE_ERROR));
  EXPECT_EQ(failures[0].scope, "stage probe/test > texture 'deliberately-bad' misuse");
  EXPECT_NE(failures[0].describe().find("GL_INVALID_OPERATION"), std::string::npos) << failures[0].describe();
  // The log holds it once, counted three times (headless runs print it once).
  int seen = 0;
  for (const auto& e : glDebugLog())
    if (e.message.scope == failures[0].scope) seen = e.count;
  EXPECT_EQ(seen, 3);
  EXPECT_TRUE(takeGLFailures().empty());
}

}  // namespace
}  // namespace voxlab
