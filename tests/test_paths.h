// Where a test finds the source tree, the dynlab binaries and its scratch folder: DYNLAB_SOURCE_DIR,
// DYNLAB_BIN, DYNLAB_UI_BIN (when the window is built) and DYNLAB_TEST_TMP, which tests/CMakeLists.txt
// defines as calls of these functions. The paths themselves are compiled into one file
// (tests/test_paths.cpp, from the generated test_build_paths.h), never into a test's compile line:
// a test source then compiles to the same bytes in every checkout, and ccache shares it across worktrees.
#pragma once

namespace dyn::test_paths {

const char* sourceDir();    // the source tree this build was configured from
const char* dynlabBin();    // the dynlab program
const char* dynlabUiBin();  // the dynlab-ui program ("" when it is not built)
const char* testTmp();      // the running test executable's folder (its test folder's build folder)

}  // namespace dyn::test_paths
