#version 450
// Depth-only pass (shadow maps): the rasterizer writes depth, nothing else is needed.
void main() {}
