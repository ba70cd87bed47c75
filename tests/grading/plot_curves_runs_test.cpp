// Tests for grading/plot_curves' masked curves ("y:x@contact": drawn only where the mask column is
// nonzero) and runSeries (the series a figure hands the plotter for one run or several overlaid):
// the points the plotter receives, their legend labels, colours and styles, and the parse errors.
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>

#include "grading/plot_curves.h"
#include "labs/lab.h"
#include "labs/run.h"

using namespace dyn;

namespace {

std::vector<std::string> sliderColumns() {
  static const auto lab = buildLab(*findLab("slider_crank"),
                                   json::parse(std::ifstream(std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/slider_crank.json")),
                                   "config.json");
  return lab->columns();
}

std::string error(const std::string& spec) {
  try {
    parsePlotCurves(spec, sliderColumns(), "<command line>", "--plot " + spec);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// A trace of columns t, x, y, m (the mask) from rows.
Trace trace(const std::vector<std::vector<double>>& rows) {
  Trace tr;
  tr.columns = {"t", "x", "y", "m"};
  for (const auto& r : rows) tr.append(r);
  return tr;
}

// [begin, end) stretches where y is finite: the pieces the plotter draws.
std::vector<std::pair<std::size_t, std::size_t>> pieces(const std::vector<double>& y) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  for (std::size_t i = 0; i < y.size();) {
    while (i < y.size() && !std::isfinite(y[i])) ++i;
    const std::size_t b = i;
    while (i < y.size() && std::isfinite(y[i])) ++i;
    if (b < i) out.push_back({b, i});
  }
  return out;
}

}  // namespace

TEST_CASE("--plot curves with a mask: Y:X@M and Y@M parse, are named, and bad masks are one line") {
  const auto cols = sliderColumns();
  const auto xy = parsePlotCurves(" q2 : q1 @ x_c , q3:q1", cols, "f", "p");
  CHECK(xy == std::vector<PlotCurve>{{"q2", "q1", "x_c"}, {"q3", "q1", ""}});
  CHECK(curvesText(xy) == "q2 vs q1 where x_c, q3 vs q1");
  CHECK(parametric(xy));
  // The same curve with and without a mask are two curves; against t a mask is allowed too.
  const auto t = parsePlotCurves("f_Ty@x_c, f_Ty", cols, "f", "p");
  CHECK(t == std::vector<PlotCurve>{{"f_Ty", "t", "x_c"}, {"f_Ty", "t", ""}});
  CHECK_FALSE(parametric(t));
  CHECK(has(error("f_Ty@"), "--plot f_Ty@: empty column name"));
  CHECK(has(error("f_Ty@zz"), "unknown column \"zz\""));
  CHECK(has(error("f_Ty@zz"), "@M to draw it only where column M is nonzero"));
  CHECK(has(error("q2:q1@x_c@x_d"), "\"q2:q1@x_c@x_d\" has two '@'"));
  CHECK(has(error("q2@x_c:q1"), "unknown column \"x_c:q1\""));
  CHECK(error("f_Ty@zz").find('\n') == std::string::npos);
}

TEST_CASE("curvePoints: where the mask is 0 (or not finite) the point is NaN, so the line breaks") {
  const Trace tr = trace({{0, 1, 10, 1}, {1, 2, 20, 1}, {2, 3, 30, 0}, {3, 4, 40, 0}, {4, 5, 50, 2}, {5, 6, 60, NAN}, {6, 7, 70, 1}});
  const CurvePoints xy = curvePoints(tr, {"y", "x", "m"});
  REQUIRE(xy.y.size() == 7);
  for (std::size_t i : {0, 1, 4, 6}) {
    CHECK(xy.x[i] == tr.at(i, "x"));
    CHECK(xy.y[i] == tr.at(i, "y"));
  }
  for (std::size_t i : {2, 3, 5}) {
    CHECK(std::isnan(xy.x[i]));
    CHECK(std::isnan(xy.y[i]));
  }
  CHECK(pieces(xy.y) == std::vector<std::pair<std::size_t, std::size_t>>{{0, 2}, {4, 5}, {6, 7}});
  // Against t the time axis stays whole: only y is masked.
  const CurvePoints ty = curvePoints(tr, {"y", "t", "m"});
  CHECK(ty.x == tr.series("t"));
  CHECK(pieces(ty.y) == pieces(xy.y));
  // No mask: the columns as they are.
  const CurvePoints plain = curvePoints(tr, {"y", "x", ""});
  CHECK(plain.x == tr.series("x"));
  CHECK(plain.y == tr.series("y"));
  CHECK_THROWS_AS(curvePoints(tr, {"y", "x", "contact"}), std::out_of_range);
}

TEST_CASE("runSeries, one run: hand solid, Bullet dashed, a curve both engines share drawn once") {
  const Trace hand = trace({{0, 0, 1, 1}, {1, 1, 2, 0}, {2, 2, 3, 1}});
  Trace bullet = hand;
  bullet.data[2] = 1.5;  // y differs in row 0; x and m are shared
  const std::vector<PlotCurve> curves{{"y", "t", ""}, {"x", "t", ""}};
  const auto s = runSeries(curves, {{"", &hand, &bullet}});
  REQUIRE(s.size() == 3);
  CHECK(s[0].label == "y (hand)");
  CHECK(s[1].label == "y (Bullet)");
  CHECK(s[2].label == "x (hand, Bullet)");
  CHECK(s[0].style == PlotSeries::Style::Solid);
  CHECK(s[1].style == PlotSeries::Style::Dashed);
  CHECK(s[0].color == s[1].color);
  CHECK(s[2].color != s[0].color);
  CHECK(s[1].y == bullet.series("y"));
  // Masked points equal on both engines (NaN beside NaN) are still one curve.
  const auto m = runSeries({{"x", "t", "m"}}, {{"", &hand, &bullet}});
  REQUIRE(m.size() == 1);
  CHECK(m[0].label == "x where m (hand, Bullet)");
  CHECK(std::isnan(m[0].y[1]));
  // One engine.
  const auto h = runSeries(curves, {{"", &hand, nullptr}});
  REQUIRE(h.size() == 2);
  CHECK(h[1].label == "x (hand)");
}

TEST_CASE("runSeries, several runs: each curve of each run named by its run; one curve for all when all agree") {
  const Trace a = trace({{0, 0, 1, 1}, {1, 1, 2, 0}, {2, 2, 3, 1}});
  Trace b = a;
  b.data[6] = 9;  // y of row 1 differs; x and m are the same in both runs
  const std::vector<PlotCurve> curves{{"y", "t", ""}, {"x", "t", ""}};
  const auto s = runSeries(curves, {{"damper.json", &a, nullptr}, {"spring.json", &b, nullptr}});
  REQUIRE(s.size() == 3);
  CHECK(s[0].label == "y (damper.json, hand)");
  CHECK(s[1].label == "y (spring.json, hand)");
  CHECK(s[2].label == "x (every run)");
  CHECK(s[2].style == PlotSeries::Style::Dashed);  // a set point on top of the responses
  CHECK(s[0].style == PlotSeries::Style::Solid);
  CHECK(s[0].y == a.series("y"));
  CHECK(s[1].y == b.series("y"));
  CHECK(s[0].color != s[1].color);
  CHECK(s[2].color != s[0].color);
  CHECK(s[2].color != s[1].color);
  // Both engines: each run's engines apart (hand solid, Bullet dashed, one colour per run), or
  // once per run when its engines agree.
  Trace a_bullet = a;
  a_bullet.data[2] = 7;
  const auto e = runSeries({{"y", "t", ""}}, {{"damper.json", &a, &a_bullet}, {"spring.json", &b, &b}});
  REQUIRE(e.size() == 3);
  CHECK(e[0].label == "y (damper.json, hand)");
  CHECK(e[1].label == "y (damper.json, Bullet)");
  CHECK(e[1].style == PlotSeries::Style::Dashed);
  CHECK(e[0].color == e[1].color);
  CHECK(e[2].label == "y (spring.json, hand, Bullet)");
  CHECK(e[2].color != e[0].color);
  // A masked overlay: each run's ink broken where its own mask is 0.
  Trace c = a;
  c.data[3] = 0, c.data[7] = 1;  // m: 0, 1, 1 instead of 1, 0, 1
  const auto k = runSeries({{"y", "x", "m"}}, {{"a", &a, nullptr}, {"c", &c, nullptr}});
  REQUIRE(k.size() == 2);
  CHECK(pieces(k[0].y) == std::vector<std::pair<std::size_t, std::size_t>>{{0, 1}, {2, 3}});
  CHECK(pieces(k[1].y) == std::vector<std::pair<std::size_t, std::size_t>>{{1, 3}});
}

TEST_CASE("runSeries, several runs with their own targets: each target in its run's colour; a shared one drawn once") {
  // y is the response, x its target; runs a and b share their target, c has its own.
  const Trace a = trace({{0, 0, 1, 1}, {1, 1, 2, 1}, {2, 1, 3, 1}});
  Trace b = a, c = a;
  b.data[6] = 2.5;             // b's response differs
  c.data[10] = 0.5;            // c's response and target differ
  c.data[5] = 0.8, c.data[9] = 0.9;
  const std::vector<PlotCurve> curves{{"y", "t", ""}, {"x", "t", ""}};
  const auto s = runSeries(curves, {{"a", &a, nullptr}, {"b", &b, nullptr}, {"c", &c, nullptr}});
  REQUIRE(s.size() == 5);
  CHECK(s[0].label == "y (a, hand)");
  CHECK(s[1].label == "y (b, hand)");
  CHECK(s[2].label == "y (c, hand)");
  CHECK(s[3].label == "x (a, b, hand)");
  CHECK(s[4].label == "x (c, hand)");
  // Every run its own colour; c's target in c's colour, dashed, its response solid.
  CHECK(s[0].color != s[1].color);
  CHECK(s[1].color != s[2].color);
  CHECK(s[0].color != s[2].color);
  CHECK(s[4].color == s[2].color);
  CHECK(s[4].y == c.series("x"));
  for (int i : {0, 1, 2}) CHECK(s[std::size_t(i)].style == PlotSeries::Style::Solid);
  CHECK(s[4].style == PlotSeries::Style::Dashed);
  // The target a and b share: once, in a colour no run has (a line under another has no entry).
  CHECK(s[3].style == PlotSeries::Style::Dashed);
  for (int i : {0, 1, 2}) CHECK(s[3].color != s[std::size_t(i)].color);
  // Two shared lines (the model's x_des beside x_target, every run's): each its own colour.
  const auto t = runSeries({{"y", "t", ""}, {"x", "t", ""}, {"m", "t", ""}}, {{"a", &a, nullptr}, {"b", &b, nullptr}});
  REQUIRE(t.size() == 4);
  CHECK(t[2].label == "x (every run)");
  CHECK(t[3].label == "m (every run)");
  CHECK(t[2].color != t[3].color);
  for (std::size_t i : {0, 1}) {
    CHECK(t[2].color != t[i].color);
    CHECK(t[3].color != t[i].color);
  }
  // No two entries of the plot draw the same line.
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t j = i + 1; j < s.size(); ++j) CHECK_FALSE((s[i].style == s[j].style && s[i].y == s[j].y && s[i].x == s[j].x));

  // Every run its own target, both engines, responses differing between engines: the target in its
  // run's colour, in a pattern of its own (not the Bullet line's).
  Trace a_bullet = a, b_bullet = b, c_bullet = c;
  a_bullet.data[10] = 7, b_bullet.data[10] = 7, c_bullet.data[10] = 8;
  b.data[5] = 0.7, b_bullet.data[5] = 0.7;
  const auto e = runSeries(curves, {{"a", &a, &a_bullet}, {"b", &b, &b_bullet}, {"c", &c, &c_bullet}});
  REQUIRE(e.size() == 9);
  for (std::size_t r = 0; r < 3; ++r) {
    const PlotSeries &hand = e[2 * r], &bullet = e[2 * r + 1], &target = e[6 + r];
    INFO(hand.label, " / ", bullet.label, " / ", target.label);
    CHECK(target.label == "x (" + std::string(1, char('a' + r)) + ", hand, Bullet)");
    CHECK(hand.color == int(r));
    CHECK(bullet.color == int(r));
    CHECK(target.color == int(r));
    CHECK(hand.style == PlotSeries::Style::Solid);
    CHECK(bullet.style == PlotSeries::Style::Dashed);
    CHECK(target.style == PlotSeries::Style::Dotted);
  }
}

TEST_CASE("the pen lab's ink: y_p against x_p where contact, broken exactly where the unstable gains lift off") {
  const std::string dir = std::string(DYNLAB_SOURCE_DIR) + "/labs/pen_on_table/";
  const LoadedLab loaded = loadLab("pen_on_table", "", dir + "examples/unstable.json", 2.6);
  const RunResult r = runEngine(*loaded.lab, Engine::Hand);
  const auto curves = parsePlotCurves("y_p:x_p@contact, y_d:x_d", loaded.lab->columns(), "f", "p");
  const auto s = runSeries(curves, {{"", &r.trace, nullptr}});
  REQUIRE(s.size() == 2);
  CHECK(s[0].label == "y_p vs x_p where contact (hand)");
  const std::vector<double> contact = r.trace.series("contact");
  for (std::size_t i = 0; i < contact.size(); ++i) {
    CHECK(std::isfinite(s[0].y[i]) == (contact[i] != 0));
    if (contact[i] != 0) CHECK(s[0].x[i] == r.trace.at(i, "x_p"));
  }
  // It touched down, lifted off and touched down again: several pieces of ink.
  CHECK(pieces(s[0].y).size() >= 3);
  // The reference circle is whole.
  CHECK(pieces(s[1].y).size() == 1);
}
