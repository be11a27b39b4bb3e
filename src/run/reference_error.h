// A technique output against the checked-in ground truth: `voxlab run` calls this for every
// output whose OutputDesc::referenceMode is set (no technique-specific code).
//
// The reference is tests/golden/reference/<scene>/<mode>.exr (under projectRoot()), rendered by
// `voxlab reference` (scripts/make-references.sh). It is used only when its metadata says the same
// scene, the same camera index and the same image size as the run, or a size that is an integer
// multiple of the output's (an output traced at reduced resolution is compared with the reference
// box-filtered down by that factor, "reference_downsampled": factor); otherwise the manifest says
// why it was skipped. Metrics are those of `voxlab compare` (reference/image_metrics.h) on the
// output's first three channels, linear, unclamped.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "capture/capture.h"
#include "graph/technique.h"

namespace voxlab {

// Where the reference for (scene, mode) would be; it may not exist.
std::string referenceImagePath(const std::string& scene, const std::string& mode);

// What a resolved reference mode counts, as the fidelity tables and sweeps name it: "direct"
// (r <= 1), "indirect" (indirect light only: indirect, indirect-K), "full" (every path), or ""
// for any other mode.
std::string referenceRole(const std::string& mode);

// Whether tests/golden/reference/<scene>/ holds any reference image (of any mode).
bool hasReferences(const std::string& scene);

// Compares 'out' (an Image2D capture, level 0) with the reference for out.desc.referenceMode,
// which must be resolved (referenceModeUnder: no {parameter} left; throws Error otherwise).
// Returns null when the output is not comparable or no reference file exists. Otherwise the
// manifest's "reference_error" object: mode, reference (path relative to the project root), spp,
// rms_stderr of the reference, mean_ratio (the output's mean over the reference's: overall energy
// bias), rmse, psnr (null when infinite), mae, mre, max_abs, ssim, dssim,
// error_scale and files ("<prefix>.error.png" and ".error.exr", written into dir: the false-colour
// luminance of |output - reference|); or {mode, reference, skipped: "why"} on a metadata mismatch.
// A reference that exists but cannot be read is reported as skipped too (the run still succeeds).
nlohmann::json compareWithReference(const CapturedOutput& out, const std::string& scene, int camera,
                                    const std::string& dir, const std::string& prefix);

// The outputs a comparison with the references writes: the technique's final output, then every
// output that declares a reference mode, in stage order.
std::vector<OutputAddress> finalAndComparedOutputs(const Technique& technique);

// Writes the reference EXR 'exr' as a PNG through the display mapping of 'desc' (its semantic and
// tone map), so that it can stand beside that output's own PNG.
void writeReferencePng(const OutputDesc& desc, const std::string& exr, const std::string& png);
DisplayImage referenceDisplayImage(const OutputDesc& desc, const std::string& exr);  // the same, as an image

// The first file of a manifest output entry ("files") whose name ends with 'suffix'; "" if none.
std::string manifestFileEndingWith(const nlohmann::json& entry, const std::string& suffix);

}  // namespace voxlab
