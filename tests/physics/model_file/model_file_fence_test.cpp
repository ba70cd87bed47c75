// The fence MuJoCo's parser runs in (physics/model_file/fence.h): what the work returns comes back
// byte for byte; its refusal keeps its message; a crash, a hang, running out of memory or a silent
// exit is one line naming the file and what happened, and the caller goes on.
#include <doctest/doctest.h>
#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "physics/model_file/fence.h"
#include "physics/model_file/model_file.h"

using namespace dyn::model_file;

namespace {

detail::FenceLimits quick() {
  detail::FenceLimits l;
  l.seconds = 1;
  l.memory_bytes = std::size_t(64) << 20;
  l.max_reply = std::size_t(4) << 20;
  return l;
}

// The error fenced() throws for work, in one line.
std::string refusal(const std::function<std::string()>& work) {
  std::string what;
  try {
    detail::fenced("f.xml", "the parser", quick(), work);
  } catch (const ModelFileError& e) {
    what = e.what();
  }
  CHECK(what.find('\n') == std::string::npos);
  return what;
}

}  // namespace

TEST_CASE("the work's reply comes back whole, binary bytes and all") {
  std::string big(3u << 20, '\0');
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = char(i * 2654435761u >> 24);
  CHECK(detail::fenced("f.xml", "the parser", quick(), [&] { return big; }) == big);
  CHECK(detail::fenced("f.xml", "the parser", quick(), [] { return std::string(); }).empty());
}

TEST_CASE("a refusal in the work keeps its message") {
  CHECK(refusal([]() -> std::string { throw ModelFileError("f.xml: 47000 bodies, more than the 1000 a model file may have"); }) ==
        "f.xml: 47000 bodies, more than the 1000 a model file may have");
}

TEST_CASE("a crash in the work is a refusal naming the signal") {
  const std::string what = refusal([]() -> std::string {
    ::raise(SIGSEGV);
    return "";
  });
  CHECK(what == "f.xml: the parser crashed on this file (signal 11, SIGSEGV)");
  CHECK(refusal([]() -> std::string { std::abort(); }).find("crashed on this file (signal 6, SIGABRT)") != std::string::npos);
}

TEST_CASE("work past its time is killed and named, within the deadline") {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string what = refusal([]() -> std::string {
    volatile unsigned long i = 0;
    for (;;) i = i + 1;
  });
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  CHECK(what == "f.xml: the parser took longer than 1 s on this file");
  CHECK(s < 10);
}

TEST_CASE("work past its memory is a refusal naming the limit") {
  // operator new's failure, and a C library's failed malloc reported through fenceOutOfMemory.
  CHECK(refusal([]() -> std::string {
          std::vector<char> v(std::size_t(512) << 20, 'x');
          return std::string(1, v[v.size() / 2]);
        }) == "f.xml: the parser ran out of memory on this file (limit 64 MiB)");
  CHECK(refusal([]() -> std::string {
          void* p = std::malloc(std::size_t(512) << 20);
          if (!p) detail::fenceOutOfMemory();
          std::memset(p, 1, std::size_t(512) << 20);
          return "";
        }) == "f.xml: the parser ran out of memory on this file (limit 64 MiB)");
}

TEST_CASE("a reply past its bound and a silent exit are refusals, not answers") {
  CHECK(refusal([] { return std::string(std::size_t(5) << 20, 'x'); }) == "f.xml: the parser answered with more than 4 MiB");
  CHECK(refusal([]() -> std::string { std::_Exit(0); }) == "f.xml: the parser ended without an answer (exit status 0)");
  CHECK(refusal([]() -> std::string { std::_Exit(3); }) == "f.xml: the parser ended without an answer (exit status 3)");
}
