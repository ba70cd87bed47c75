// dynlab check-results: a Gradescope results.json checked for its shape; see check_results.h.
// The file is read without blocking (O_NONBLOCK, then fstat), checked to be UTF-8, parsed with
// nlohmann/json, then walked key by key against Gradescope's fields; the first problem is reported.
#include "app/cli/course/check_results.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "grading/escape.h"
#include "labs/utf8.h"

namespace dyn::app {
namespace {

using nlohmann::json;
using Pointer = json::json_pointer;
using Field = std::function<void(const json&, const Pointer&)>;

// The first problem found: where (a JSON pointer, "" for the whole file), what was expected, what was there.
struct Invalid {
  std::string where, expected, got;
};

// Gradescope's allowed values (see the course staff's notes on the results.json format).
const std::vector<std::string> kFormats = {"text", "html", "simple_format", "md", "ansi"};
const std::vector<std::string> kVisibilities = {"visible", "hidden", "after_due_date", "after_published"};

// Cuts s to at most n bytes without splitting a UTF-8 sequence.
std::string clip(std::string s, std::size_t n) {
  if (s.size() <= n) return s;
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;
  return s.substr(0, n) + "...";
}

// How a value is named in a message: its JSON text when short, else its kind.
std::string describe(const json& v) {
  if (v.is_object()) return "an object";
  if (v.is_array()) return "an array";
  if (v.is_number_float() && !std::isfinite(v.get<double>())) return "a number too large for a double";
  return clip(v.dump(), 40);
}

std::string choices(const std::vector<std::string>& set) {
  std::string out;
  for (const auto& s : set) out += (out.empty() ? "\"" : ", \"") + s + "\"";
  return out;
}

[[noreturn]] void fail(const Pointer& at, const std::string& expected, const std::string& got) {
  throw Invalid{at.to_string(), expected, got};
}

// Field checks: each names the expected type and the value found.
void number(const json& v, const Pointer& at) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) fail(at, "a number", describe(v));
}
void text(const json& v, const Pointer& at) {
  if (!v.is_string()) fail(at, "a string", describe(v));
}
void object(const json& v, const Pointer& at) {
  if (!v.is_object()) fail(at, "an object", describe(v));
}
Field oneOf(const std::vector<std::string>& set) {
  return [set](const json& v, const Pointer& at) {
    if (!v.is_string() || std::find(set.begin(), set.end(), v.get<std::string>()) == set.end())
      fail(at, "one of " + choices(set), describe(v));
  };
}
void strings(const json& v, const Pointer& at) {
  if (!v.is_array()) fail(at, "an array of strings", describe(v));
  for (std::size_t i = 0; i < v.size(); ++i) text(v[i], at / i);
}

// An object whose keys are all known, each checked by its field; `required` keys (key, what) must be there.
void fields(const json& v, const Pointer& at, const std::map<std::string, Field>& known,
            const std::vector<std::pair<std::string, std::string>>& required = {}) {
  object(v, at);
  for (const auto& [key, what] : required)
    if (!v.contains(key)) fail(at / key, what + " (the key is required)", "nothing");
  for (const auto& [key, value] : v.items()) {
    const auto f = known.find(key);
    if (f == known.end()) {
      std::string keys;
      for (const auto& [k, unused] : known) keys += (keys.empty() ? "" : ", ") + k;
      fail(at / key, "one of Gradescope's keys here (" + keys + ")", "an unknown key");
    }
    f->second(value, at / key);
  }
}

void test(const json& v, const Pointer& at) {
  static const std::map<std::string, Field> known = {
      {"name", text},          {"number", text},    {"score", number},          {"max_score", number},
      {"status", oneOf({"passed", "failed"})},      {"output", text},           {"output_format", oneOf(kFormats)},
      {"name_format", oneOf(kFormats)},             {"tags", strings},          {"visibility", oneOf(kVisibilities)},
      {"extra_data", object}};
  fields(v, at, known);
}

void leader(const json& v, const Pointer& at) {
  static const std::map<std::string, Field> known = {{"name", text}, {"value", number}, {"order", oneOf({"asc", "desc"})}};
  fields(v, at, known, {{"name", "a string"}, {"value", "a number"}});
}

Field arrayOf(void (*each)(const json&, const Pointer&)) {
  return [each](const json& v, const Pointer& at) {
    if (!v.is_array()) fail(at, "an array", describe(v));
    for (std::size_t i = 0; i < v.size(); ++i) each(v[i], at / i);
  };
}

// The whole file: Gradescope's top-level keys; without a total score, every test needs its own.
void results(const json& v) {
  static const std::map<std::string, Field> known = {
      {"score", number},        {"execution_time", number},           {"output", text},
      {"output_format", oneOf(kFormats)},                             {"test_output_format", oneOf(kFormats)},
      {"test_name_format", oneOf(kFormats)},                          {"visibility", oneOf(kVisibilities)},
      {"stdout_visibility", oneOf(kVisibilities)},                    {"extra_data", object},
      {"tests", arrayOf(test)}, {"leaderboard", arrayOf(leader)}};
  if (!v.is_object()) fail(Pointer(), "a JSON object", describe(v));
  fields(v, Pointer(), known);
  if (v.contains("score")) return;
  if (!v.contains("tests") || v["tests"].empty())
    fail(Pointer("/score"), "a number (there are no tests whose scores could make the total)", "nothing");
  for (std::size_t i = 0; i < v["tests"].size(); ++i)
    if (!v["tests"][i].contains("score"))
      fail(Pointer("/tests") / i / "score", "a number (there is no top-level /score)", "nothing");
}

// strerror's text, lower-cased to continue a sentence ("no such file or directory").
std::string errorText(int err) {
  std::string s = std::strerror(err);
  if (!s.empty()) s[0] = char(std::tolower(static_cast<unsigned char>(s[0])));
  return s;
}

// The file's bytes, or why they cannot be had; opened non-blocking so a FIFO never hangs.
bool readRegular(const std::string& file, std::string& bytes, std::string& why) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) {
    why = "expected a readable file, got " + errorText(errno);
    return false;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    const char* kind = S_ISDIR(st.st_mode) ? "a directory" : S_ISFIFO(st.st_mode) ? "a FIFO" : S_ISSOCK(st.st_mode) ? "a socket"
                       : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device" : "something else";
    ::close(fd);
    why = std::string("expected a regular file, got ") + kind;
    return false;
  }
  char buf[1 << 16];
  for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      why = "expected a readable file, got " + errorText(errno);
      ::close(fd);
      return false;
    }
    bytes.append(buf, std::size_t(n));
  }
  ::close(fd);
  return true;
}

// One line for a terminal and for a JSON string: grading/escape.h's terminal text (control bytes,
// in keys say, and bytes that are not UTF-8 become \xNN), clipped.
std::string oneLine(const std::string& s) { return clip(termText(s), 400); }

}  // namespace

std::string resultsProblem(const std::string& file) {
  std::string bytes, why;
  if (!readRegular(file, bytes, why)) return oneLine(file + ": " + why);
  if (bytes.empty()) return oneLine(file + ": expected a JSON object, got an empty file");
  if (const std::size_t at = utf8ErrorAt(bytes); at != std::string::npos) {
    char got[64];
    std::snprintf(got, sizeof got, "byte 0x%02x at offset %zu", static_cast<unsigned char>(bytes[at]), at);
    return oneLine(file + ": expected UTF-8 text, got " + got);
  }
  if (bytes.rfind("\xEF\xBB\xBF", 0) == 0) return oneLine(file + ": expected JSON text, got a byte-order mark first");
  json v;
  try {
    v = json::parse(bytes);
  } catch (const json::exception& e) {
    // nlohmann's text after its "[json.exception.KIND.N] " tag says where and what (or which number overflowed).
    const std::string what = e.what();
    const std::size_t tag = what.find("] ");
    return oneLine(file + ": expected JSON, got " + (tag == std::string::npos ? what : what.substr(tag + 2)));
  }
  try {
    results(v);
  } catch (const Invalid& e) {
    return oneLine(file + ": " + (e.where.empty() ? "(the whole file)" : e.where) + ": expected " + e.expected +
                   ", got " + e.got);
  }
  return "";
}

int checkResults(const std::string& file) {
  const std::string problem = resultsProblem(file);
  if (!problem.empty()) {
    std::fprintf(stderr, "error: %s\n", problem.c_str());
    return 2;
  }
  std::printf("%s: a valid Gradescope results.json\n", oneLine(file).c_str());
  return 0;
}

}  // namespace dyn::app
