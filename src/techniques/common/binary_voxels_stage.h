// BinaryVoxelsStage: the voxel fragment list as a binary voxel grid of 128-bit columns (seed 000
// section 3.2.1 and 4.4.4, after Thiedemann et al. 2011): one RGBA32UI texel per (x, y) column of
// the voxel volume, one bit per depth slice along the volume's z axis (the voxelization axis).
//
// Bit order (every user of the grid): slice k in [0,127] covers unit z in [k/128, (k+1)/128); it
// is bit 31 - (k & 31) (counting from the LSB) of channel k >> 5 (R, G, B, A). So bits are MSB
// first: slice 0 is R's 0x80000000, slice 127 is A's bit 0.
//
// Slices are fixed at 128 by the format. The xy resolution is voxel.resolution; a voxel of the
// fragment list at depth z covers slices [z * 128 / res, (z + 1) * 128 / res) when res <= 128 (so
// at res = 128 the grid equals the dense occupancy bit for bit) and slice z * 128 / res above.
//
// Built exactly from the conservative fragment list (not from the thesis' texture atlas): one
// compute invocation per fragment ORs its slice bits with imageAtomicOr into an R32UI image four
// texels wide per column ("binary-voxels.words"), then a pass packs the four words into the
// RGBA32UI grid. An R32UI *view* of the RGBA32UI texture is not allowed (GL 4.5 table 8.22: the
// 128-bit and 32-bit view classes differ; tests/unit/test_near_field.cpp checks the error), so
// the words live in their own texture. On llvmpipe both this and the thesis' logic-op OR (points
// into an RGBA32UI target with glLogicOp(GL_OR)) work (tests: NearFieldGrid.*); the atomics need
// no point list and no framebuffer.
//
// Reads "fragments", "fragments.count". Outputs "binary-voxels" (RGBA32UI columns) and
// "binary-popcount" (set slices per column).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "graph/stage.h"

namespace voxlab {

using BitColumn = std::array<uint32_t, 4>;  // R, G, B, A words of one 128-slice column

// Images of 128-bit columns in this bit order (the grid, near-field's hierarchy and tables):
// src/techniques/near_field/views/bitmask_columns.cpp shows a picked column as a stack of slices.
inline constexpr Semantic kBitmaskColumns{"bitmask-columns"};

constexpr int kBinarySlices = 128;
inline int sliceChannel(int k) { return k >> 5; }
inline uint32_t sliceBit(int k) { return 0x80000000u >> (k & 31); }
inline bool hasSlice(const BitColumn& c, int k) { return (c[sliceChannel(k)] & sliceBit(k)) != 0; }
inline void setSlice(BitColumn& c, int k) { c[sliceChannel(k)] |= sliceBit(k); }
int popcount(const BitColumn& c);

// Slices [first, last] that voxel depth z of a res^3 fragment list covers.
void slicesOfVoxel(int z, int res, int& first, int& last);

// The CPU reference: the grid (res * res columns, row-major, x fastest) from voxel keys packed
// 10:10:10 as the fragment list stores them.
std::vector<BitColumn> binaryGridFromVoxelKeys(const std::vector<uint32_t>& keys, int res);

// Reads level 'level' of an RGBA32UI texture back as columns (exact: no float conversion).
std::vector<BitColumn> readBitColumns(GLuint texture, int level, int width, int height);

class BinaryVoxelsStage : public Stage {
 public:
  const char* id() const override { return "binary-voxels"; }
  const char* title() const override { return "Binary voxel grid (128-bit columns)"; }
  const char* summary() const override {
    return "OR each voxel fragment's slice bit into its column: a 2D RGBA32UI texture whose 128 bits "
           "per texel are the voxels along the depth axis.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

}  // namespace voxlab
