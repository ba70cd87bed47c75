// Labs outside the dynlab tree: a lecturer's folder of lab folders, named by `--labs DIR` on a
// command or by DYNLAB_LABS (a ':'-separated list of such folders). Each data lab folder found there
// (DIR/<name>/<name>.json, no .cpp or .h: data_lab.h) is registered after the tree's labs, which stay
// visible. The rule for names: a lab outside the tree may not take the name of a tree lab or of a lab
// in another outside folder; such a clash is refused (InputError, one line naming both folders), never
// resolved by order. A folder whose name is not a lab name ([a-z][a-z0-9_]*, at most 40) but holds
// its <name>.json is refused the same way; other folders (no <name>.json, or C++) are not labs and are
// passed over, as in the tree.
#pragma once
#include <string>
#include <vector>

namespace dyn::generic {

// One folder of lab folders and who named it, for messages: the InputError's file and path
// ("<command line>" and "--labs", "<environment>" and "DYNLAB_LABS").
struct LabsFolder {
  std::string path;
  std::string origin = "--labs";
  std::string source = "<command line>";
};

// The folders DYNLAB_LABS names, in order (empty entries skipped; none when it is unset).
std::vector<LabsFolder> labsFoldersFromEnvironment();

// Registers the data labs of each folder after the tree's. A folder given twice (or the tree's own
// labs/) is used once; labs are registered under their folder's absolute path. Throws InputError
// (file: the folder's source, path: its origin) for a folder that does not exist, a
// path holding ':' (it could not be passed on in DYNLAB_LABS), a folder named unlike a lab, or a name
// clash; a folder with a clash registers none of its labs.
void useLabsFolders(const std::vector<LabsFolder>& folders);

// The absolute folders registered so far, in order: what DYNLAB_LABS must say for another dynlab
// process (a check-lab run, a batch's grader, the window) to find the same labs.
std::vector<std::string> labsFoldersInUse();

}  // namespace dyn::generic
