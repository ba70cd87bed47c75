// Trace helpers: column lookup, CSV, fingerprint.
#include "labs/trace.h"

#include <cctype>
#include <cstdio>
#include <stdexcept>

#include "labs/utf8.h"

namespace dyn {

int Trace::column(const std::string& name) const {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return int(i);
  return -1;
}

int Trace::require(const std::string& name) const {
  const int c = column(name);
  if (c < 0) throw std::out_of_range("the trace has no column \"" + name + "\"");
  return c;
}

std::vector<double> Trace::series(const std::string& name) const {
  const int c = column(name);
  std::vector<double> out;
  if (c < 0) return out;
  out.reserve(rows());
  for (std::size_t r = 0; r < rows(); ++r) out.push_back(at(r, c));
  return out;
}

std::string Trace::csv() const {
  std::string s;
  // A name from a lab's JSON may hold anything: each header one CSV field (quoted, no formula, no ESC).
  for (std::size_t i = 0; i < columns.size(); ++i) s += (i ? "," : "") + csvField(columns[i]);
  s += '\n';
  char buf[32];
  for (std::size_t r = 0; r < rows(); ++r) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      std::snprintf(buf, sizeof buf, "%.17g", at(r, int(c)));
      if (c) s += ',';
      s += buf;
    }
    s += '\n';
  }
  return s;
}

std::string columnName(const std::string& name) {
  std::string out;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ? c : '_';
  // A long name (a model file may name a joint with 200,000 characters) keeps its start and a hash
  // of the whole: a header of a few dozen characters, still one per name.
  if (out.size() > kMaxColumnName) {
    char hash[24];
    std::snprintf(hash, sizeof hash, "_%016llx", static_cast<unsigned long long>(fnv1a(name.data(), name.size())));
    out = out.substr(0, kMaxColumnName - 17) + hash;
  }
  return out.empty() ? "_" : out;
}

std::uint64_t fnv1a(const void* bytes, std::size_t n) {
  std::uint64_t h = 1469598103934665603ull;
  const auto* p = static_cast<const unsigned char*>(bytes);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

std::uint64_t Trace::hash() const { return fnv1a(data.data(), data.size() * sizeof(double)); }

}  // namespace dyn
