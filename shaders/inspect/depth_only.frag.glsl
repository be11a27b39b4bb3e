#version 450
// Writes no colour: depth comes from rasterization.
void main() {}
