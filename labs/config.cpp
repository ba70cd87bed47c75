// JsonView: typed, path-aware reads of lab configs and submissions (see config.h).
#include "labs/config.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>
#include <vector>

#include "labs/utf8.h"

namespace dyn {

namespace {
// A key as a JSON Pointer token (RFC 6901): "~" is written "~0" and "/" is written "~1".
std::string pointerToken(const std::string& key) {
  std::string out;
  for (const char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}
}  // namespace

InputError::InputError(std::string file, std::string path, const std::string& expected)
    // The message is one line of text a terminal shows as it is, whatever the input held: control
    // characters (a newline or an ESC in a key, a scenario name, a file name), C1 and bidi controls
    // and invalid bytes written as escapes (termText).
    : std::runtime_error(termText(clipText(file) + ": " + (path.empty() ? "/" : clipText(path)) + ": " + clipText(expected, 600))),
      file_(utf8Quotable(clipText(file))), path_(utf8Quotable(clipText(path))), expected_(utf8Quotable(clipText(expected, 600))) {}

namespace {
// Where the parser is, for the JSON path of a duplicate key: one frame per open object or array.
struct ParseFrame {
  bool object;
  std::set<std::string> keys;  // keys seen so far (objects)
  std::string key;             // the current key (objects)
  std::size_t done = 0;        // elements completed so far (arrays): the next one's index
};

std::string framePath(const std::vector<ParseFrame>& frames) {
  std::string path;
  for (const ParseFrame& f : frames) path += "/" + (f.object ? pointerToken(f.key) : std::to_string(f.done));
  return path;
}

// nlohmann's parse error without its tag and without "last read: '...'", which quotes the input
// (a symlinked /etc/passwd must not be echoed into a student's feedback).
std::string parseErrorText(const std::string& what) {
  const auto tag = what.find("] ");
  std::string s = what.substr(tag == std::string::npos ? 0 : tag + 2);
  const auto read = s.find("; last read: '");
  if (read != std::string::npos) {
    // What follows the quoted token is nlohmann's own text ("'; expected ..."), found from the end.
    const auto expected = s.rfind("'; expected ");
    s = s.substr(0, read) + (expected != std::string::npos && expected > read ? s.substr(expected + 1) : "");
  }
  return s;
}
}  // namespace

json parseJsonText(const std::string& text, const std::string& file) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw InputError(file, "", "expected a JSON document, the file is empty");
  try {
    // Nesting is bounded: copying, dumping or patching a json recurses once per level, so a few
    // hundred KB of "[[[[…" would overflow the stack. Real configs nest 6 levels.
    // Keys are tracked per object: a duplicate is refused (nlohmann would keep the last silently).
    std::vector<ParseFrame> frames;
    const auto completed = [&] {
      if (!frames.empty() && !frames.back().object) ++frames.back().done;
    };
    const json::parser_callback_t check = [&](int level, json::parse_event_t event, json& parsed) {
      using E = json::parse_event_t;
      const bool opens = event == E::object_start || event == E::array_start;
      if (opens && level >= kMaxJsonDepth)
        throw InputError(file, framePath(frames),
                         "expected JSON nested at most " + std::to_string(kMaxJsonDepth) + " levels deep");
      if (opens) frames.push_back({event == E::object_start, {}, {}, 0});
      if (event == E::key) {
        ParseFrame& f = frames.back();
        f.key = parsed.get<std::string>();
        if (!f.keys.insert(f.key).second)
          throw InputError(file, framePath(frames), "duplicate key \"" + f.key + "\" (each key may appear once in an object)");
      }
      if (event == E::object_end || event == E::array_end) {
        frames.pop_back();
        completed();
      }
      if (event == E::value) completed();
      return true;
    };
    return json::parse(text, check);
  } catch (const json::exception& e) {
    // nlohmann's message names the line and column (parse_error) or the number that does not fit a
    // double, e.g. 1e999 (out_of_range 406).
    throw InputError(file, "", "expected valid JSON (" + parseErrorText(e.what()) + ")");
  }
}

void JsonView::fail(const std::string& expected) const { throw InputError(file_, path_, expected); }

std::string JsonView::got() const {
  // dump() writes a non-finite double (only possible in memory) as null: name it instead.
  if (value_->is_number_float() && !std::isfinite(value_->get<double>()))
    return std::isnan(value_->get<double>()) ? ", got NaN" : value_->get<double>() > 0 ? ", got inf" : ", got -inf";
  // A value built in memory may hold invalid UTF-8: replaced, so the message can always be made.
  std::string s = value_->dump(-1, ' ', false, json::error_handler_t::replace);
  if (s.size() > 40) {
    std::size_t n = 37;
    while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;  // not mid-character
    s = s.substr(0, n) + "...";
  }
  return ", got " + s;
}

bool JsonView::has(const std::string& key) const { return value_->is_object() && value_->contains(key); }

void JsonView::requireObject() const {
  if (!value_->is_object()) fail("expected an object" + got());
}

JsonView JsonView::operator[](const std::string& key) const {
  requireObject();
  const auto it = value_->find(key);
  if (it == value_->end()) fail("missing key \"" + key + "\"");
  return JsonView(*it, file_, path_ + "/" + pointerToken(key));
}

JsonView JsonView::at(std::size_t index) const {
  if (!value_->is_array() || index >= value_->size())
    fail("expected an array with an element " + std::to_string(index));
  return JsonView((*value_)[index], file_, path_ + "/" + std::to_string(index));
}

std::size_t JsonView::size(std::size_t min, std::size_t max) const {
  if (!value_->is_array()) fail("expected an array" + got());
  const std::size_t n = value_->size();
  if (n < min || n > max) {
    fail(min == max ? "expected an array of " + std::to_string(min) + " elements, got " + std::to_string(n)
                    : "expected an array of " + std::to_string(min) + " to " + std::to_string(max) +
                          " elements, got " + std::to_string(n));
  }
  return n;
}

void JsonView::onlyKeys(std::initializer_list<const char*> allowed) const {
  requireObject();
  for (const auto& [key, _] : value_->items()) {
    bool ok = false;
    for (const char* a : allowed) ok = ok || key == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      JsonView(value_->at(key), file_, path_ + "/" + pointerToken(key)).fail("unknown key \"" + key + "\" (expected one of: " + list + ")");
    }
  }
}

double JsonView::number() const {
  if (!value_->is_number()) fail("expected a number" + got());
  const double x = value_->get<double>();
  if (!std::isfinite(x)) fail("expected a finite number" + got());
  return x;
}

double JsonView::positive() const {
  const double x = number();
  if (!(x > 0)) fail("expected a positive number" + got());
  return x;
}

double JsonView::positive(double max) const {
  const double x = positive();
  if (!(x <= max)) {
    std::ostringstream s;
    s << "expected a positive number ≤ " << max << got();
    fail(s.str());
  }
  return x;
}

double JsonView::nonNegative() const {
  const double x = number();
  if (!(x >= 0)) fail("expected a number ≥ 0" + got());
  return x;
}

double JsonView::inRange(double lo, double hi) const {
  const double x = number();
  if (!(x >= lo && x <= hi)) {
    std::ostringstream s;
    s << "expected a number in [" << lo << ", " << hi << "]" << got();
    fail(s.str());
  }
  return x;
}

long long JsonView::integer(long long lo, long long hi) const {
  if (!value_->is_number_integer()) fail("expected an integer" + got());
  const long long x = value_->get<long long>();
  if (x < lo || x > hi)
    fail("expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]" + got());
  return x;
}

bool JsonView::boolean() const {
  if (!value_->is_boolean()) fail("expected true or false" + got());
  return value_->get<bool>();
}

std::string JsonView::string() const {
  if (!value_->is_string()) fail("expected a string" + got());
  return value_->get<std::string>();
}

std::string JsonView::oneOf(std::initializer_list<const char*> choices) const {
  std::string list;
  for (const char* c : choices) list += std::string(list.empty() ? "" : ", ") + "\"" + c + "\"";
  if (!value_->is_string()) fail("expected one of " + list + got());
  const std::string s = value_->get<std::string>();
  for (const char* c : choices)
    if (s == c) return s;
  fail("expected one of " + list + got());
}

json mergePatch(json target, const json& patch) {
  target.merge_patch(patch);
  return target;
}

}  // namespace dyn
