// The Gradescope autograder bundle for one lab: a zip whose root holds setup.sh (installs the
// packages and builds dynlab when Gradescope builds the image), run_autograder (grades one
// submission and always leaves a valid results.json), README.md (for the course staff), and the
// dynlab source tree under source/.
#pragma once
#include <string>

namespace dyn::app {

// Writes a Gradescope autograder zip for `lab` at zip_path (root: setup.sh, run_autograder,
// README.md, and the dynlab source tree under source/). Throws std::runtime_error naming the path.
// source_dir: the dynlab source tree (DYNLAB_SOURCE_DIR). Deterministic bytes (fixed mtimes, sorted entries).
// lab_folder: the lab's folder when it is outside the tree (--labs DIR): packed as source/labs/<lab>/,
// so the bundle's tree has the lab (its instructor/ left out, as the tree's labs' are).
void writeAutograder(const std::string& lab, const std::string& source_dir, const std::string& zip_path,
                     const std::string& lab_folder = "");

}  // namespace dyn::app
