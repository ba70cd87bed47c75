// Loop closures given beside a model file (URDF cannot express loops): a small JSON file naming pairs
// of links, with a point in each link's frame, to `connect` (3 translation rows) or `weld` (6 rows).
// Read here (app/: physics includes no JSON) into model_file::GivenClosure, plain data the loader
// holds exactly as it holds MJCF <equality> connect and weld (dependent rows dropped the same way).
//
//   { "loops": [ { "name": "pin_C", "kind": "connect",
//                  "body1": "coupler", "point1": [0.4, 0, 0.1],
//                  "body2": "rocker",  "point2": [-0.1, 0, 0.3] } ] }      // point2 optional
//
// Found beside a URDF as STEM.loops.json (fourbar.urdf → fourbar.loops.json), or named with
// `dynlab model FILE --loops JSON` (any model file).
#pragma once
#include <string>
#include <vector>

#include "physics/model_file/model_file.h"

namespace dyn::app {

// The closures in JSON. Throws model_file::ModelFileError, one line: "JSON: loops[0].point1: expected
// ..., got ...".
std::vector<model_file::GivenClosure> readLoops(const std::string& json);

// STEM.loops.json beside a URDF file (.urdf, any case) when it exists (a regular file or not), else ""
// (an MJCF file writes its loops as equalities: fourbar.xml does not pick up fourbar.urdf's loops).
std::string loopsBeside(const std::string& model);

// The model with its closures: LOOPS when given, else the file beside it, else the file's own only.
model_file::LoadedModel loadWithLoops(const std::string& model, const std::string& loops, model_file::LoadOptions options = {});

}  // namespace dyn::app
