// Packing helpers. Voxel coordinates use 10 bits per axis (x in bits 0-9, y 10-19, z 20-29),
// which limits a grid to 1024^3 (Basgier's voxel fragment list, seed 002 section 3.5.1).
uint packVoxel10(uvec3 v) { return (v.x & 1023u) | ((v.y & 1023u) << 10) | ((v.z & 1023u) << 20); }
uvec3 unpackVoxel10(uint p) { return uvec3(p & 1023u, (p >> 10) & 1023u, (p >> 20) & 1023u); }
