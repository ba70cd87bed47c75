// Out of memory is exit 1 with one line ("error: out of memory: ..."), never a signal: the three
// commands that died under `ulimit -v` 400–550 MB (SIGSEGV in the OSMesa context's teardown, SIGTRAP
// from GLib under PLplot's cairo driver, SIGABRT from llvmpipe's LLVM) run here under an address-space
// limit set in the child (setrlimit, as ulimit -v does). Where memory runs out depends on the machine
// (llvmpipe's thread count, the address layout), so each may also succeed; what it may never do is end
// by a signal, print more than one line, or exit 3. The limits are two where the binary before the fix
// died by SIGSEGV (run --video at 400, figure at 425 MiB) and SIGTRAP (figure at 400) or said only
// "error: std::bad_alloc" (model --video); each command fails or finishes in a second or two.
#include <doctest/doctest.h>

#include "tests/app/cli_run.h"
#include "tests/app/limited_run.h"

using dyn::test::cli::TempDir;
using namespace dyn::test::limited;

namespace {

void endsCleanly(const Ended& r, const std::string& command, int limit_mib) {
  INFO(command << " under " << limit_mib << " MiB: exit " << r.code << ", signal " << r.signal << ", stderr: " << r.err);
  CHECK(r.signal == 0);
  CHECK((r.code == 0 || r.code == 1));
  if (r.code == 1) {
    CHECK(lineCount(r.err) == 1);
    CHECK(r.err.rfind("error: out of memory: ", 0) == 0);
    CHECK(r.err.find("under the address-space limit of " + std::to_string(limit_mib) + " MiB") != std::string::npos);
  }
}

}  // namespace

TEST_CASE("run --video, figure and model --video under a memory limit: exit 0, or 1 with one line, never a signal") {
  TempDir dir("memory_limit");
  const std::string puma = std::string(DYNLAB_SOURCE_DIR) + "/assets/models/puma560.urdf";
  const std::vector<std::vector<std::string>> commands = {
      {"run", "fivebar", "--video", "--out", "run"}, {"figure", "fivebar", "--out", "figure"}, {"model", puma, "--video", "--out", "model"}};
  for (int limit : {400, 425})
    for (const auto& args : commands) {
      const Ended r = runDynlab(dir.path, args, double(limit) * 1024 * 1024, 60);
      endsCleanly(r, args[0] + " " + args[1], limit);
    }
}
