// The build's paths for the tests (tests/test_paths.h), from the header tests/CMakeLists.txt generates.
#include "tests/test_paths.h"

#include <climits>
#include <string>
#include <unistd.h>

#include "test_build_paths.h"

namespace dyn::test_paths {

const char* sourceDir() { return kSourceDir; }
const char* dynlabBin() { return kDynlabBin; }
const char* dynlabUiBin() { return kDynlabUiBin; }

const char* testTmp() {
  static const std::string dir = [] {
    char buf[PATH_MAX];
    const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
    if (n <= 0) return std::string(".");
    const std::string exe(buf, std::size_t(n));
    const std::size_t slash = exe.rfind('/');
    return slash == std::string::npos ? std::string(".") : exe.substr(0, slash);
  }();
  return dir.c_str();
}

}  // namespace dyn::test_paths
