// The voxel volume: an axis-aligned cube of u_resolution^3 voxels of edge u_voxelSize (metres)
// whose minimum corner is u_volumeOrigin. Voxel (i,j,k) covers origin + [i,i+1) * voxelSize ...
uniform vec3 u_volumeOrigin;
uniform float u_voxelSize;
uniform float u_voxelsPerMetre;  // 1 / u_voxelSize, computed on the CPU (VoxelSpace::voxelsPerMetre)
uniform int u_resolution;

// The same two correctly rounded operations as VoxelSpace::toVoxel on the CPU (precise: no
// reassociation), so the CPU reference voxelizer sees the GPU's coordinates, ties included.
vec3 worldToVoxel(vec3 p) {
  precise vec3 v = (p - u_volumeOrigin) * u_voxelsPerMetre;
  return v;
}
vec3 voxelToWorld(vec3 v) { return u_volumeOrigin + v * u_voxelSize; }
// Normalised texture coordinates [0,1]^3 of a world position.
vec3 worldToVolumeUV(vec3 p) { return worldToVoxel(p) / float(u_resolution); }
