// labs/trace.h: columns by name and by a Column looked up once read the same numbers; a missing
// column throws (once there is a row to read); the fingerprint is FNV-1a over the raw doubles.
#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>

#include "labs/trace.h"

using namespace dyn;

namespace {

Trace sample() {
  Trace tr;
  tr.columns = {"t", "x", "energy"};
  for (int r = 0; r < 5; ++r) tr.append({0.001 * r, 1.5 - 0.25 * r * r, 3.0 + r});
  return tr;
}

}  // namespace

TEST_CASE("a Column reads what at(row, name) reads, row by row") {
  const Trace tr = sample();
  const auto x = tr.col("x"), energy = tr.col("energy");
  CHECK(x.index == 1);
  for (std::size_t r = 0; r < tr.rows(); ++r) {
    CHECK(x[r] == tr.at(r, "x"));
    CHECK(energy[r] == tr.at(r, "energy"));
  }
  CHECK(x[3] == 1.5 - 0.25 * 9);
}

TEST_CASE("a missing column throws once the trace has rows, as a lookup by name does") {
  const Trace tr = sample();
  CHECK_THROWS_AS(tr.col("y"), std::out_of_range);
  CHECK_THROWS_AS(tr.at(0, "y"), std::out_of_range);
  Trace empty;
  empty.columns = {"t"};
  CHECK(empty.rows() == 0);
  CHECK_NOTHROW(empty.col("y"));  // nothing will be read: no row, no throw (as before)
  CHECK(empty.steps() == 0);
  CHECK(tr.steps() == 4);
}

TEST_CASE("the fingerprint is FNV-1a 64 over the raw doubles, and sees every bit") {
  Trace tr = sample();
  const std::uint64_t h = tr.hash();
  CHECK(h == fnv1a(tr.data.data(), tr.data.size() * sizeof(double)));
  // dynlab's basis (labs/trace.h: a digit short of FNV's); FNV-1a's step from it: (basis ^ 'a') × prime.
  CHECK(fnv1a("", 0) == 1469598103934665603ull);
  CHECK(fnv1a("a", 1) == (1469598103934665603ull ^ 0x61u) * 1099511628211ull);
  CHECK(fnv1a("ab", 2) == (((1469598103934665603ull ^ 0x61u) * 1099511628211ull) ^ 0x62u) * 1099511628211ull);
  tr.data[7] = std::nextafter(tr.data[7], 10.0);
  CHECK(tr.hash() != h);
}
