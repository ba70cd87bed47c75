// util/pipe.h: what readPipe keeps and says when the writer closes, writes too much (stopping or
// draining) or stays silent past the deadline.
#include "physics/util/pipe.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <string>

using namespace dyn;

namespace {

// A pipe holding `bytes` (written before the read), its write end closed unless keep_open.
struct Pipe {
  int fds[2] = {-1, -1};
  explicit Pipe(const std::string& bytes, bool keep_open = false) {
    REQUIRE(::pipe(fds) == 0);
    writeAll(fds[1], bytes);
    if (!keep_open) closeWriter();
  }
  void closeWriter() {
    if (fds[1] >= 0) ::close(fds[1]);
    fds[1] = -1;
  }
  ~Pipe() {
    closeWriter();
    ::close(fds[0]);
  }
};

}  // namespace

TEST_CASE("readPipe: everything up to the writer's close") {
  Pipe p("answer");
  const PipeRead r = readPipe(p.fds[0], 10, 100, Overflow::Stop);
  CHECK(r.bytes == "answer");
  CHECK_FALSE(r.late);
  CHECK_FALSE(r.large);
}

TEST_CASE("readPipe past the bound: Stop keeps nothing of the read that passed it, Keep the first bytes") {
  {
    Pipe p("0123456789");
    const PipeRead r = readPipe(p.fds[0], 10, 4, Overflow::Stop);
    CHECK(r.large);
    CHECK(r.bytes.empty());
  }
  {
    Pipe p("0123456789");
    const PipeRead r = readPipe(p.fds[0], 10, 4, Overflow::Keep);
    CHECK(r.large);
    CHECK_FALSE(r.late);
    CHECK(r.bytes == "0123");
  }
  {
    Pipe p("0123");  // exactly the bound: not large
    const PipeRead r = readPipe(p.fds[0], 10, 4, Overflow::Stop);
    CHECK_FALSE(r.large);
    CHECK(r.bytes == "0123");
  }
}

TEST_CASE("readPipe: a writer that stays open is late at the deadline, with what it wrote") {
  Pipe p("partial", true);
  const PipeRead r = readPipe(p.fds[0], 0.2, 100, Overflow::Keep);
  CHECK(r.late);
  CHECK(r.bytes == "partial");
}
