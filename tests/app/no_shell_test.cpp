// No shell anywhere in the tree (issue 39): every C/C++ source and header, Python file, shell
// script, CMake file and scripts/* under the source tree is scanned for the ways a program hands a
// command line to a shell — std::system / system(...), popen, "/bin/sh", an exec or argument
// vector of `sh -c`, `sh -c` on a build or script line, Python's os.system, subprocess with
// shell=True or a command given as one string — and each hit is named as file:line. A program is
// run with an argument vector instead (app/shared/process.h; tests/app/cli_run.h in the tests). The one
// line allowed carries kException: a test that runs the command line dynlab prints for a user to
// paste into a shell, which is the point of that test. The build trees and .git are not scanned.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const std::string kException = "// a user's shell: the test checks the command line printed for pasting";

struct Pattern {
  std::string what;
  std::regex re;
};

// Each way to reach a shell, as a regular expression on one line.
const std::vector<Pattern>& patterns() {
  static const std::vector<Pattern> p = {
      {"std::system", std::regex(R"(std::system\s*\()")},
      {"system() call", std::regex(R"((^|[^\w.])system\()")},
      {"popen", std::regex(R"(\bpopen\s*\()")},
      {"\"/bin/sh\"", std::regex(R"(["'](/usr)?/bin/(ba|da)?sh["'])")},
      {"sh -c as arguments", std::regex(R"(["'](/usr)?(/bin/)?(ba|da)?sh["']\s*,\s*["']-c["'])")},
      {"exec of a shell", std::regex(R"(\bexecl[pe]?\s*\(.*\b(ba|da)?sh\b)")},
      {"sh -c", std::regex(R"((^|[^\w-])(ba|da)?sh\s+-c\b)")},
      {"os.system", std::regex(R"(\bos\.system\s*\()")},
      {"shell=True", std::regex(R"(\bshell\s*=\s*True\b)")},
      {"subprocess with a command string", std::regex(R"(\bsubprocess\.\w+\(\s*[rbf]?["'])")},
  };
  return p;
}

// What a line does to reach a shell ("" if nothing; a line with kException is allowed).
std::string shellUse(const std::string& line) {
  if (line.find(kException) != std::string::npos) return "";
  // Every pattern holds one of these words: lines without any need no regular expression (quick).
  bool candidate = false;
  for (const char* word : {"sh", "system", "popen", "subprocess"}) candidate = candidate || line.find(word) != std::string::npos;
  if (!candidate) return "";
  for (const Pattern& p : patterns())
    if (std::regex_search(line, p.re)) return p.what;
  return "";
}

// The files scanned: sources, headers, Python, shell scripts, CMake files and everything in scripts/.
bool scanned(const fs::path& relative) {
  static const std::vector<std::string> extensions = {".cpp", ".cc", ".c", ".h", ".hpp", ".py", ".sh", ".cmake", ".ipynb"};
  const std::string ext = relative.extension().string();
  return *relative.begin() == "scripts" || relative.filename() == "CMakeLists.txt" ||
         std::find(extensions.begin(), extensions.end(), ext) != extensions.end();
}

// A folder not scanned: .git, and a build tree (build*/ at the top, or any folder CMake configured).
bool skipped(const fs::path& dir, const fs::path& root) {
  const std::string name = dir.filename().string();
  return name == ".git" || (dir.parent_path() == root && name.rfind("build", 0) == 0) || fs::exists(dir / "CMakeCache.txt");
}

// Every line under root that reaches a shell, as "FILE:LINE: WHAT: the line".
std::vector<std::string> shellUses(const fs::path& root) {
  std::vector<std::string> hits;
  const fs::path self = "tests/app/no_shell_test.cpp";
  for (auto it = fs::recursive_directory_iterator(root, fs::directory_options::skip_permission_denied);
       it != fs::recursive_directory_iterator(); ++it) {
    if (it->is_directory() && !it->is_symlink()) {
      if (skipped(it->path(), root)) it.disable_recursion_pending();
      continue;
    }
    const fs::path relative = fs::relative(it->path(), root);
    if (!it->is_regular_file() || !scanned(relative) || relative == self) continue;
    std::ifstream in(it->path(), std::ios::binary);
    int number = 0;
    for (std::string line; std::getline(in, line);) {
      ++number;
      const std::string what = shellUse(line);
      if (!what.empty()) hits.push_back(relative.string() + ":" + std::to_string(number) + ": " + what + ": " + line);
    }
  }
  return hits;
}

}  // namespace

TEST_CASE("the scan: each way to reach a shell is found; an argument vector, names and prose are not") {
  for (const char* line : {
           R"(  const int status = std::system(cmd.c_str());)",
           R"(  if (system("ls") != 0) return;)",
           R"(  FILE* f = popen(cmd.c_str(), "r");)",
           R"(  ::execl("/bin/sh", "sh", "-c", cmd.c_str(), nullptr);)",
           R"(  ::execlp("bash", "bash", script, nullptr);)",
           R"(  const char* argv[] = {"/bin/sh", "-c", text, nullptr};)",
           R"(  runProgram({"sh", "-c", hint});)",
           R"(  run(dir, {"bash", "-c", "command -v python3"});)",
           R"(      COMMAND sh -c "gzip -dc '${IN}' > '${OUT}'")",
           R"(out=$(bash -c "$cmd"))",
           R"(    os.system("dynlab run " + lab))",
           R"(    subprocess.run(cmd, shell=True, check=True))",
           R"(    subprocess.check_output("dynlab list"))",
           R"(    subprocess.run(f"{CLI} grade {path}"))",
       }) {
    CHECK_MESSAGE(!shellUse(line).empty(), "not found: " << line);
  }
  for (const char* line : {
           R"(    throw std::system_error(errno, std::generic_category(), "cannot write " + path);)",
           R"(// MuJoCo's virtual file system (VFS) holds the checked files)",
           R"(    return subprocess.run([CLI, *args], capture_output=True, cwd=TMP))",
           R"(  runProgram({"git", "-C", DYNLAB_SOURCE_DIR, "ls-files"}, o);)",
           R"(  run(dir, {"bash", "bundle/run_autograder"}, env);)",
           R"(#!/usr/bin/env bash)",
           R"(#!/bin/sh)",
           R"(  const std::string shell = "zsh";  // the user's)",
           R"(  o.unset_env = {"DISPLAY", "WAYLAND_DISPLAY"};)",
       }) {
    CHECK_MESSAGE(shellUse(line).empty(), "taken for a shell: " << line);
  }
  // The one exception is a line carrying its comment, word for word.
  CHECK(shellUse(R"(  run(dir, {"sh", "-c", hint}, o);  )" + kException).empty());
  CHECK_FALSE(shellUse(R"(  run(dir, {"sh", "-c", hint}, o);  // a user's shell)").empty());
}

TEST_CASE("no std::system, popen or sh -c in the tree: programs are run with argument vectors") {
  const std::vector<std::string> hits = shellUses(DYNLAB_SOURCE_DIR);
  for (const std::string& hit : hits) FAIL_CHECK(hit);
  CHECK(hits.size() == 0);
}
