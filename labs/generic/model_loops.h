// Loop closures and dynlab's own constraint elements given beside a model file (URDF cannot express
// loops; neither MJCF nor URDF has a rolling wheel or a unilateral plane contact): a small JSON file
// naming pairs of links to `connect` (3 translation rows) or `weld` (6 rows), wheels that roll without
// slip, and balls that touch a plane. Read here (app/: physics includes no JSON) into
// model_file::GivenClosure / GivenRolling / GivenContact, plain data the loader turns into the same
// constraint kinds a lab's C++ writes (physics/constraints: point_closure, rolling, plane_contact).
//
//   { "loops":    [ { "name": "pin_C", "kind": "connect",
//                     "body1": "coupler", "point1": [0.4, 0, 0.1],
//                     "body2": "rocker",  "point2": [-0.1, 0, 0.3] } ],            // point2 optional
//     "rolling":  [ { "name": "wheel", "body": "wheel", "centre": [0, 0, 0], "axle": [0, 1, 0],
//                     "radius": 0.1, "height": 0, "mu": 0.8 } ],                  // ground z = height
//     "contacts": [ { "name": "tip", "body": "forearm", "point": [0.35, 0, 0], "radius": 0.005,
//                     "normal": [0, 0, 1], "height": 0.1, "mu": 0, "stiffness": 0, "damping": 0 } ] }
//
// Found beside a URDF as STEM.loops.json (fourbar.urdf → fourbar.loops.json), beside an MJCF file the
// same way unless a URDF of that stem stands beside it too (the JSON is then the URDF's), or named with
// `dynlab model FILE --loops JSON` (any model file).
#pragma once
#include <string>
#include <vector>

#include "physics/model_file/model_file.h"

namespace dyn::app {

// The closures, wheels and contacts in JSON, appended to options' lists. Throws
// model_file::ModelFileError, one line: "JSON: loops[0].point1: expected ..., got ...".
void readBeside(const std::string& json, model_file::LoadOptions& options);

// STEM.loops.json beside a URDF file (.urdf, any case) when it exists (a regular file or not), or beside
// an MJCF file (.xml) when no STEM.urdf stands there too (fourbar.xml does not pick up fourbar.urdf's
// loops), else "".
std::string loopsBeside(const std::string& model);

// The model with its closures: LOOPS when given, else the file beside it, else the file's own only.
model_file::LoadedModel loadWithLoops(const std::string& model, const std::string& loops, model_file::LoadOptions options = {});

}  // namespace dyn::app
