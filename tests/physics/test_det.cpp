// physics/det (issue 46): the layer's accuracy against x87 long double, its C99 special values, the
// normal deviates' transform, and that no std:: transcendental or std::normal_distribution is back in
// physics/ (but physics/bullet and physics/det), labs/, grading/ or app/.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "physics/det/det.h"
#include "physics/det/normal.h"
#include "physics/det/rotation.h"

namespace {

// |got − ref| in units of the last place of the double nearest ref.
double ulps(double got, long double ref) {
  const double r = double(ref);
  int e;
  std::frexp(r, &e);
  return double(std::fabs((long double)got - ref)) / std::ldexp(1.0, std::max(e - 53, -1074));
}

template <class D, class R>
double worst(D f, R ref, double lo, double hi, bool log_scale = false) {
  std::mt19937_64 g(46);
  std::uniform_real_distribution<double> u(lo, hi);
  double w = 0;
  for (int i = 0; i < 100000; ++i) {
    const double x = log_scale ? std::exp(u(g)) : u(g);
    w = std::max(w, ulps(f(x), ref((long double)x)));
  }
  return w;
}

bool same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || (a == b && std::signbit(a) == std::signbit(b)); }

}  // namespace

TEST_CASE("det's functions are within their documented ulps of long double") {
  using L = long double;
  CHECK(worst([](double x) { return det::sin(x); }, [](L x) { return sinl(x); }, -1e5, 1e5) < 1.0);
  CHECK(worst([](double x) { return det::cos(x); }, [](L x) { return cosl(x); }, -1e5, 1e5) < 1.0);
  CHECK(worst([](double x) { return det::tan(x); }, [](L x) { return tanl(x); }, -10, 10) < 2.5);
  CHECK(worst([](double x) { return det::asin(x); }, [](L x) { return asinl(x); }, -1, 1) < 1.0);
  CHECK(worst([](double x) { return det::acos(x); }, [](L x) { return acosl(x); }, -1, 1) < 1.0);
  CHECK(worst([](double x) { return det::atan(x); }, [](L x) { return atanl(x); }, -30, 30, true) < 1.0);
  CHECK(worst([](double x) { return det::exp(x); }, [](L x) { return expl(x); }, -700, 700) < 1.0);
  CHECK(worst([](double x) { return det::log(x); }, [](L x) { return logl(x); }, -700, 700, true) < 1.0);
  CHECK(worst([](double x) { return det::log2(x); }, [](L x) { return log2l(x); }, -700, 700, true) < 0.51);
  CHECK(worst([](double x) { return det::log10(x); }, [](L x) { return log10l(x); }, -700, 700, true) < 0.51);
  CHECK(worst([](double x) { return det::tanh(x); }, [](L x) { return tanhl(x); }, -3, 3) < 3.0);
  CHECK(worst([](double x) { return det::atan2(x, 0.7); }, [](L x) { return atan2l(x, (long double)0.7); }, -10, 10) < 1.5);
  CHECK(worst([](double x) { return det::hypot(x, 3.1); }, [](L x) { return sqrtl(x * x + (long double)3.1 * (long double)3.1); }, -10, 10) < 0.51);
  CHECK(worst([](double x) { return det::pow(1.7, x); }, [](L x) { return powl((long double)1.7, x); }, -100, 100) < 1.5);
  CHECK(worst([](double x) { return det::pow(x, -2.3); }, [](L x) { return powl(x, (long double)-2.3); }, 0.01, 100) < 1.5);
}

TEST_CASE("det's special values are C99's, and exact cases stay exact") {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> special = {0.0, -0.0, inf, -inf, nan}, plain = {1.0, -1.0, 2.0, 0.5};
  std::vector<double> xs = special;
  xs.insert(xs.end(), plain.begin(), plain.end());
  for (double x : {0.0, -0.0, inf, -inf, nan, 1.0, -1.0}) {
    CAPTURE(x);
    CHECK(same(det::sin(x), std::sin(x)));
    CHECK(same(det::asin(x), std::asin(x)));
    CHECK(same(det::acos(x), std::acos(x)));
    CHECK(same(det::atan(x), std::atan(x)));
    CHECK(same(det::log(x), std::log(x)));
    CHECK(same(det::log2(x), std::log2(x)));
    CHECK(same(det::log10(x), std::log10(x)));
    CHECK(same(det::tanh(x), std::tanh(x)));
  }
  for (double x : xs)
    for (double y : xs) {
      CAPTURE(x);
      CAPTURE(y);
      const bool either = std::count(special.begin(), special.end(), x) || std::count(special.begin(), special.end(), y) ||
                          std::isnan(x) || std::isnan(y);
      if (either) CHECK(same(det::atan2(x, y), std::atan2(x, y)));
      if (either) CHECK(same(det::hypot(x, y), std::hypot(x, y)));
      CHECK(same(det::pow(x, y), std::pow(x, y)));  // the plain pairs: exact, or a square root
    }
  CHECK(std::isfinite(det::sin(1e300)));  // reduced, if not accurately, far out
  for (int k = -22; k <= 22; ++k) {
    CHECK(det::pow(10.0, k) == std::pow(10.0, k));
    CHECK(det::log10(det::pow(10.0, k)) == k);
  }
  for (int k = -1074; k <= 1023; ++k) CHECK(det::log2(std::ldexp(1.0, k)) == k);
}

TEST_CASE("det::Normal is the polar method over 64 random bits (libstdc++'s order, det::log)") {
  std::mt19937_64 a(7), b(7);
  det::Normal n;
  // The documented transform, step by step.
  const auto uniform = [&] { return double(b()) * 0x1p-64; };
  double x, y, s;
  do {
    x = 2.0 * uniform() - 1.0, y = 2.0 * uniform() - 1.0, s = x * x + y * y;
  } while (s > 1.0 || s == 0.0);
  const double f = std::sqrt(-2.0 * det::log(s) / s);
  CHECK(n(a) == y * f);
  CHECK(n(a) == x * f);
  // A 32-bit engine: two draws make one uniform.
  std::mt19937 c(9), d(9);
  det::Normal m;
  const auto uniform32 = [&] {
    const double lo = double(d());
    return (lo + double(d()) * 0x1p32) * 0x1p-64;
  };
  do {
    x = 2.0 * uniform32() - 1.0, y = 2.0 * uniform32() - 1.0, s = x * x + y * y;
  } while (s > 1.0 || s == 0.0);
  CHECK(m(c) == y * std::sqrt(-2.0 * det::log(s) / s));
  // Standard normal: mean 0, variance 1 (200 000 draws: 5 standard errors).
  double sum = 0, sum2 = 0;
  const int count = 200000;
  for (int i = 0; i < count; ++i) {
    const double z = n(a);
    sum += z, sum2 += z * z;
  }
  CHECK(std::abs(sum / count) < 5 / std::sqrt(double(count)));
  CHECK(std::abs(sum2 / count - 1.0) < 5 * std::sqrt(2.0 / count));
}

TEST_CASE("det::rotationVector is Eigen's angle-axis") {
  for (const Eigen::Vector3d w : {Eigen::Vector3d(0.3, -0.2, 0.9), Eigen::Vector3d(0, 0, 3.0), Eigen::Vector3d(1e-9, 0, 0)}) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    const Eigen::AngleAxisd e(R);
    CHECK((det::rotationVector(R) - e.angle() * e.axis()).norm() < 1e-15);
  }
  CHECK(det::rotationVector(Eigen::Matrix3d::Identity()).norm() == 0.0);
  CHECK((det::rotationZ(0.4) - Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix()).norm() < 1e-16);
}

TEST_CASE("no std:: transcendental, normal_distribution or Eigen angle-axis outside physics/det and physics/bullet") {
  namespace fs = std::filesystem;
  const std::regex banned(
      R"(std::(sin|cos|tan|asin|acos|atan|atan2|sinh|cosh|tanh|asinh|acosh|atanh|exp|exp2|expm1|log|log2|log10|log1p|pow|hypot|cbrt|erf|erfc|tgamma|lgamma|arg|polar)\s*\(|normal_distribution|AngleAxis|slerp|\.eulerAngles\()");
  std::vector<std::string> found;
  for (const char* dir : {"physics", "labs", "grading", "app"}) {
    for (const auto& entry : fs::recursive_directory_iterator(fs::path(DYNLAB_SOURCE_DIR) / dir)) {
      const std::string rel = fs::relative(entry.path(), DYNLAB_SOURCE_DIR).generic_string();
      const std::string ext = entry.path().extension().string();
      if (!entry.is_regular_file() || (ext != ".cpp" && ext != ".h")) continue;
      if (rel.starts_with("physics/bullet/") || rel.starts_with("physics/det/")) continue;
      std::ifstream in(entry.path());
      int line_no = 0;
      for (std::string line; std::getline(in, line);) {
        ++line_no;
        const std::string code = line.substr(0, line.find("//"));
        if (std::regex_search(code, banned)) found.push_back(rel + ":" + std::to_string(line_no) + ": " + line);
      }
    }
  }
  std::ostringstream all;
  for (const auto& f : found) all << f << "\n";
  INFO("use det:: (physics/det/det.h, normal.h, rotation.h) instead:\n" << all.str());
  CHECK(found.empty());
}
