// Reading lab configs and submissions: every value is read through a JsonView that knows its
// file and JSON path, so bad input becomes one clear line —
//   "labs/x.json: /links/0/mass: expected a positive number, got -1"
// and never a crash or a half-written result.
#pragma once
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace dyn {

using nlohmann::json;

// Bad input: the file, the JSON path and what was expected. All three are kept as valid UTF-8
// (an invalid byte of a file name or value is written \xNN), so they can go into JSON as they are,
// and clipped (clipText: 300 bytes, 600 for what was expected), so a 900 KB key is never quoted whole.
class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::string path, const std::string& expected);
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  const std::string& expected() const { return expected_; }

 private:
  std::string file_, path_, expected_;
};

// Deepest nesting of arrays and objects a loaded JSON document may have.
inline constexpr int kMaxJsonDepth = 64;

// Reads a whole text file: a regular file only (a FIFO, device, socket or directory is refused
// at once, never waited on), at most max_bytes, valid UTF-8 without NUL bytes (UTF-16 is named as
// such). Throws InputError naming the file, and the offset of a bad byte.
std::string readTextFile(const std::string& file, std::size_t max_bytes);
// The UTF-8 part of readTextFile, for text from elsewhere.
void checkUtf8Text(const std::string& text, const std::string& file);

// Reads a whole JSON file (readTextFile; a leading UTF-8 byte order mark is accepted and skipped);
// throws InputError for a missing, empty, oversized, non-UTF-8, malformed or too deeply nested
// file, and for a key repeated in one object (with its JSON path).
json loadJsonFile(const std::string& file, std::size_t max_bytes = 16u << 20);
json parseJsonText(const std::string& text, const std::string& file);

class JsonView {
 public:
  JsonView(const json& value, std::string file, std::string path = "")
      : value_(&value), file_(std::move(file)), path_(std::move(path)) {}

  const json& raw() const { return *value_; }
  const std::string& file() const { return file_; }
  std::string path() const { return path_.empty() ? "/" : path_; }

  bool has(const std::string& key) const;
  JsonView operator[](const std::string& key) const;  // required key of an object
  JsonView at(std::size_t index) const;               // element of an array
  std::size_t size(std::size_t min = 0, std::size_t max = SIZE_MAX) const;  // array length
  void requireObject() const;
  // Rejects keys other than those listed (typos in a config must not pass silently).
  void onlyKeys(std::initializer_list<const char*> allowed) const;

  double number() const;  // finite number
  double positive() const;
  double positive(double max) const;  // in (0, max]
  double nonNegative() const;
  double inRange(double lo, double hi) const;
  long long integer(long long lo, long long hi) const;  // long long: 64 bits in WebAssembly too
  bool boolean() const;
  std::string string() const;
  std::string oneOf(std::initializer_list<const char*> choices) const;

  double number(const std::string& key, double fallback) const {
    return has(key) ? (*this)[key].number() : fallback;
  }

  [[noreturn]] void fail(const std::string& expected) const;

 private:
  std::string got() const;  // the offending value, short
  const json* value_;
  std::string file_, path_;
};

// RFC 7386 merge patch (scenario overrides, gains onto a config).
json mergePatch(json target, const json& patch);

}  // namespace dyn
