// A model file (MJCF or URDF, with what stands beside it: STEM.loops.json) where a lab name goes, for
// the commands that work on a lab's run: `dynlab figure FILE` and the tuning window `dynlab ui FILE`.
// The file is read once into a lab of its own (no actuated joint, no task): its passive motion from
// its pose at rest, at the file's step, both engines, run as `dynlab model` runs it (labs/generic/model_run.h:
// with wheels or contacts, stepped as the labs step, the touchdowns' losses in the books), its trace
// `dynlab model`'s columns and each joint's bearing load (load_JOINT_x|y|z). Shared by dynlab and
// dynlab-ui (part of dynlab_labs, beside the data lab it resembles).
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "labs/run.h"

namespace dyn::app {

// What the command line adds to a model file's load (dynlab model, run, figure, bench: --ignore-contacts,
// --package-path DIR, --key NAME).
struct ModelFileFlags {
  bool ignore_contacts = false;            // geoms that may collide: not noted (they load either way)
  std::vector<std::string> package_paths;  // folders holding package://NAME/… packages
  std::string key;                         // a keyframe of the file to start from (its qpos, qvel, ctrl)
};

// True when LAB names a model file (ends in .xml or .urdf, any case) or its description (.json:
// model_description.h): no lab's name does.
bool isModelFile(const std::string& name);

// The model file as a lab, passive, for `duration` s (default 2 s), with the closures, wheels and
// contacts beside it; its figures are the coordinates, the energy books (with the touchdowns' losses),
// each closure's force and each wheel's or contact's.
// Throws InputError (one line, naming the file) on bad input. notes, when given: what a run of it should
// say once (model_run.h's modelNotes at the file's step).
LoadedLab loadModelLab(const std::string& file, std::optional<double> duration, const ModelFileFlags& flags = {},
                       std::vector<std::string>* notes = nullptr);

// Names joined by sep ("q_crank, q_rocker"; "x z"): a model's columns and rows in figures and summaries.
std::string join(const std::vector<std::string>& v, const char* sep = " ");

}  // namespace dyn::app
