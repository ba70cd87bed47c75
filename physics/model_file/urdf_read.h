// What a URDF's elements say about the files MuJoCo 2.2.2 reads and what it drops (urdf_read.cpp):
// read through tinyxml2 (the XML library MuJoCo itself links), so a <visual>, <mimic> or
// discardvisual inside a comment or CDATA counts for nothing, and quoting and spacing are XML's.
#pragma once

#include <cstddef>
#include <set>
#include <string>

namespace dyn::model_file::detail {

struct UrdfFacts {
  bool well_formed = false;    // false: nothing below was read (MuJoCo's parser says where the text breaks)
  bool keeps_visuals = false;  // <robot><mujoco><compiler discardvisual="false"/> (MuJoCo discards visuals by default)
  std::set<std::string> visual_only;  // file names (file… attributes) written inside <visual> elements and nowhere else
  std::size_t mimics = 0;             // <mimic> elements
};

UrdfFacts readUrdfFacts(const std::string& text);

}  // namespace dyn::model_file::detail
