// A model file compiled to dynlab's own description (issue 42 item 4): a JSON document holding what
// physics/model_file's LoadedModel holds — the tree (each body's joint, axis, placement and 6×6 inertia,
// the ball joints), the joints' springs and friction, every constraint (the loops' kept rows, every row
// of every closure, joint limits, couplings, wheels, contacts), the actuators and tendons, the start,
// timestep and gravity, and what the pictures need (geoms, meshes' triangles, colours) — every double
// written so that it reads back to the same bits (nlohmann's shortest round-trip text). A reader builds
// the same LoadedModel from it without MuJoCo, so a run of the description is the run of the file, bit
// for bit (tests/labs/model_description_test.cpp), and the WebAssembly grader grades the model-file labs
// from descriptions scripts/web exports at build time (docs/web.md "Model descriptions").
//   dynlab model FILE --export DESC.json     writes one (app/cli/model)
// Wherever a lab or a command names a model file (.xml, .urdf), a description (.json) may stand.
#pragma once
#include <string>

#include "labs/config.h"
#include "physics/model_file/model_file.h"

namespace dyn::app {

inline constexpr const char* kDescriptionFormat = "dynlab model description";
inline constexpr int kDescriptionVersion = 1;
// A description larger than this is refused before it is parsed.
inline constexpr std::size_t kMaxDescriptionBytes = 64u << 20;

// True when PATH names a description (ends in .json, any case).
bool isDescription(const std::string& path);

// The description of a loaded model as JSON. Throws ModelFileError for what it cannot hold (payloads,
// external forces, a constraint kind a model file never makes).
json describeModel(const model_file::LoadedModel& m);
// As text (indented), the way --export writes it.
std::string descriptionText(const model_file::LoadedModel& m);

// The model a description at PATH holds (file: PATH; no MuJoCo model inside: `compiled` is null). The
// options a model file's load takes apply as they can: joint_limits false leaves the limits out (noted,
// as a data lab's load does); key must be the one it was exported with, or empty; closures, wheels and
// contacts beside it are refused (a description holds its own). Throws ModelFileError: one line naming
// PATH, the JSON path and what was expected (an unknown format version included).
model_file::LoadedModel readDescription(const std::string& path, const model_file::LoadOptions& options = {});
// The same from text already read (file: the name errors give).
model_file::LoadedModel readDescriptionText(const std::string& text, const std::string& file, const model_file::LoadOptions& options = {});

// A model file or a description, whichever PATH names; a model file through MuJoCo's parser
// (model_file::load), or, once descriptionsOnly() was set, through its exported description there.
model_file::LoadedModel loadModelOrDescription(const std::string& path, const model_file::LoadOptions& options = {});

// Where a build without MuJoCo's parser (the WebAssembly grader, the page) finds the descriptions of the
// model files labs name: FOLDER/REL.json for the file at TREE/REL (REL relative to the dynlab tree, e.g.
// FOLDER/assets/models/puma560.urdf.json), as scripts/web exports them. A model file without one there
// is refused in one line saying how to export it. "" (the default): model files are parsed.
void setDescriptionsFolder(const std::string& folder);
// FOLDER/REL.json for a model file PATH inside the dynlab tree ("" when it lies outside it).
std::string descriptionFor(const std::string& folder, const std::string& path);

}  // namespace dyn::app
