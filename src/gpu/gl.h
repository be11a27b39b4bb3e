// The one include for OpenGL 4.5 core: the glad loader generated at build time.
#pragma once
#include <glad/gl.h>
