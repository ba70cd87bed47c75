// app/shared/process.h: a program run from an argument vector, never a shell. An argument holding $(...),
// spaces or quotes arrives as it is; the child's folder, stdin/stdout files and environment are as
// asked; a deadline kills it; a missing program is an error, not a crash. startProgram/waitProgram:
// two programs at once (a reader and a writer of one FIFO, which neither finishes alone) and a
// signal sent to a started one.
#include "app/shared/process.h"

#include <doctest/doctest.h>
#include <signal.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/test_files.h"

namespace fs = std::filesystem;
using namespace dyn;

namespace {

fs::path scratch(const std::string& name) { return test::scratchDir("process", name); }

void write(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

}  // namespace

TEST_CASE("runProgram: each argument is one argument, whatever it holds; folder, files and environment as asked") {
  const fs::path dir = scratch("argv");
  ProcessOptions o;
  o.cwd = dir.string();
  o.stdout_file = (dir / "out.txt").string();
  const ProcessResult r = runProgram({"printf", "[%s]", "$(touch injected)", "a 'b' \"c\"", "x;y", ""}, o);
  CHECK(r.started());
  CHECK(r.code == 0);
  CHECK(test::readBytes(dir / "out.txt") == "[$(touch injected)][a 'b' \"c\"][x;y][]");
  CHECK_FALSE(fs::exists(dir / "injected"));

  write(dir / "in.txt", "from the file\n");
  o.stdin_file = (dir / "in.txt").string();
  CHECK(runProgram({"cat"}, o).code == 0);
  CHECK(test::readBytes(dir / "out.txt") == "from the file\n");

  ::setenv("DYNLAB_PROCESS_TEST_GONE", "1", 1);
  o.stdin_file.clear();
  o.set_env = {{"DYNLAB_PROCESS_TEST", "a b=c"}};
  o.unset_env = {"DYNLAB_PROCESS_TEST_GONE"};
  CHECK(runProgram({"env"}, o).code == 0);
  const std::string env = test::readBytes(dir / "out.txt");
  CHECK(env.find("\nDYNLAB_PROCESS_TEST=a b=c\n") != std::string::npos);
  CHECK(env.find("DYNLAB_PROCESS_TEST_GONE") == std::string::npos);
  ::unsetenv("DYNLAB_PROCESS_TEST_GONE");

  o.set_env.clear();
  CHECK(runProgram({"pwd", "-P"}, o).code == 0);
  CHECK(test::readBytes(dir / "out.txt") == fs::canonical(dir).string() + "\n");
}

TEST_CASE("runProgram: a missing program is an error line and exit 127; a deadline kills the child") {
  const ProcessResult missing = runProgram({"dynlab-no-such-program"});
  CHECK_FALSE(missing.started());
  CHECK(missing.code == 127);
  CHECK(missing.error.find("dynlab-no-such-program") != std::string::npos);
  CHECK_FALSE(runProgram({}).started());

  ProcessOptions o;
  o.timeout_s = 0.2;
  const ProcessResult slow = runProgram({"sleep", "30"}, o);
  CHECK(slow.timed_out);
  CHECK(slow.signal == SIGKILL);
  CHECK(slow.code == 128 + SIGKILL);
}

TEST_CASE("startProgram / waitProgram: two programs at once, and a signal to a started one") {
  const fs::path dir = scratch("started");
  write(dir / "message.txt", "through the FIFO\n");
  REQUIRE(::mkfifo((dir / "fifo").c_str(), 0600) == 0);
  ProcessOptions reader;
  reader.cwd = dir.string();
  reader.stdout_file = (dir / "read.txt").string();
  reader.timeout_s = 60;  // a reader left alone would wait for a writer for ever
  // The reader blocks until the writer opens the FIFO: only both running at once finish.
  StartedProgram cat = startProgram({"cat", "fifo"}, reader);
  REQUIRE(cat.pid > 0);
  ProcessOptions writer;
  writer.cwd = dir.string();
  writer.stdin_file = (dir / "message.txt").string();
  writer.stdout_file = (dir / "fifo").string();
  writer.timeout_s = 60;
  StartedProgram copy = startProgram({"cat"}, writer);
  const ProcessResult wrote = waitProgram(copy), read = waitProgram(cat);
  CHECK(wrote.code == 0);
  CHECK(read.code == 0);
  CHECK_FALSE(read.timed_out);
  CHECK(test::readBytes(dir / "read.txt") == "through the FIFO\n");

  StartedProgram sleeper = startProgram({"sleep", "30"});
  REQUIRE(sleeper.pid > 0);
  REQUIRE(::kill(sleeper.pid, SIGTERM) == 0);
  const ProcessResult stopped = waitProgram(sleeper);
  CHECK(stopped.signal == SIGTERM);
  CHECK(stopped.code == 128 + SIGTERM);
  CHECK(sleeper.pid == -1);  // waited for: nothing left to signal

  StartedProgram missing = startProgram({"dynlab-no-such-program"});
  CHECK(missing.pid == -1);
  CHECK(waitProgram(missing).code == 127);
}
