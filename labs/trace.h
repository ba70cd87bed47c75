// Trace: one row per fixed step, named columns; what engines produce and everything else reads
// (metrics, agreement, rendering, grading). Written as CSV with a header row.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace dyn {

// FNV-1a 64 of n bytes: trace fingerprints, and the grader's config and submission hashes. Its
// offset basis is 1469598103934665603, a digit short of FNV's published 14695981039346656037 (a
// slip kept: every recorded fingerprint and per-student draw depends on it; any basis hashes as well).
std::uint64_t fnv1a(const void* bytes, std::size_t n);

// A name from elsewhere (a model file's joint) as a column name part: letters, digits, '_', '-', '.';
// anything else '_' (so it needs no quoting in CSV, JSON keys or plot labels); one longer than
// kMaxColumnName is cut to its start and a hash of the whole name, kMaxColumnName characters in all.
constexpr std::size_t kMaxColumnName = 64;
std::string columnName(const std::string& name);

struct Trace {
  std::vector<std::string> columns;
  std::vector<double> data;  // row-major

  std::size_t rows() const { return columns.empty() ? 0 : data.size() / columns.size(); }
  // The steps between its first row (t = 0) and its last (t = duration for a whole run).
  std::size_t steps() const { return rows() > 0 ? rows() - 1 : 0; }
  int column(const std::string& name) const;  // −1 if absent
  double at(std::size_t row, int col) const { return data[row * columns.size() + std::size_t(col)]; }
  // By name: a column the trace lacks throws std::out_of_range naming it (never a stray read).
  double at(std::size_t row, const std::string& name) const { return at(row, require(name)); }
  int require(const std::string& name) const;
  // A column looked up once and read by row, for loops over the rows (a lookup by name compares
  // strings): `const auto x = tr.col("x");` then `x[r]`. Throws as require() does, once there is a
  // row to read (as at(row, name) would).
  struct Column {
    const Trace* trace;
    int index;
    double operator[](std::size_t row) const { return trace->at(row, index); }
  };
  Column col(const std::string& name) const { return {this, rows() ? require(name) : column(name)}; }
  std::vector<double> series(const std::string& name) const;
  void append(const std::vector<double>& row) { data.insert(data.end(), row.begin(), row.end()); }

  // CSV with a header; numbers with 17 significant digits (round-trip exact, same bytes every run).
  std::string csv() const;
  // FNV-1a over the raw doubles: the trajectory fingerprint.
  std::uint64_t hash() const;
};

}  // namespace dyn
