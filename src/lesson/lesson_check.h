// What `voxlab lesson --check` verifies beyond a lesson's step blocks (parseLesson): that its text
// says only things that are true of the program and the repository, and that every step's picture
// shows something.
//
// Text (lessonTextProblems), each problem as "FILE:LINE: what is wrong; what would be valid":
//   - step numbers come from one place, the order of the step blocks: the narrative of step N holds
//     exactly one heading "## Step N: title", and a "step K" in the prose names a step that exists;
//   - every file the text names exists: backticked repository paths (src/..., shaders/..., a `*`
//     matches within a name) and relative Markdown links;
//   - every output the text names exists: a backticked "technique/stage/output" or, for the step's
//     own technique, "stage/output";
//   - every viewer key the text names ("key I", "press F5") is one the viewer handles;
//   - nothing cites the project's private source numbering ("seed 000"): a student cannot look it
//     up; cite the paper or thesis by author and year.
//
// Pictures (pictureDetail): the share of a step picture's pixels that stand out from its dominant
// colour. A picture whose share is under kBlankPictureDetail is blank: an empty slice, an all-zero
// difference, a 2x2 view, a handful of points on a 512x512 page.
#pragma once
#include <string>
#include <vector>

#include "capture/capture.h"
#include "lesson/lesson.h"

namespace voxlab {

// 'text' is the lesson file's text (parsed into 'lesson'); paths resolve against the lesson's
// folder (links) and the project root (backticked paths).
std::vector<std::string> lessonTextProblems(const Lesson& lesson, const std::string& text);

// The keys the viewer handles, as a lesson may name them ("I", "F5", "Page Down", "Escape", ...).
const std::vector<std::string>& viewerKeyNames();

// Share of pixels (0..1) that differ by more than 12 of 255 in some channel from the mean colour of
// the most common colour (colours quantized to 16 levels per channel to find it).
double pictureDetail(const DisplayImage& image);

// Under 0.09 % of the pixels is blank. The smallest subject a shipped step shows on purpose is one
// cell of a 32x32 slice (lesson 05's single light source: 1/1024 = 0.098 %); the blank pictures
// this rejects measured 0.00 % (an empty slice, an all-zero difference, a 2x2 view of one value)
// and 0.05 % (forty cone samples drawn as 2-pixel points on 512x512, before point splats were
// sized to the record count: 1.1-1.2 % now).
constexpr double kBlankPictureDetail = 0.0009;

}  // namespace voxlab
