// Measured numbers in a README, checked against a run; see readme_numbers.h.
#include "app/cli/authoring/readme_numbers.h"

#include <cmath>
#include <cstdlib>
#include <regex>

#include "labs/numbers.h"
#include "physics/det/det.h"

namespace dyn {

std::vector<ReadmeNumber> readmeNumbers(const std::string& text) {
  static const std::regex marked(R"(([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)<!-- measured: (\S*) -->)");
  std::vector<ReadmeNumber> out;
  int line = 1;
  std::size_t counted = 0;  // newlines counted up to here
  for (auto it = std::sregex_iterator(text.begin(), text.end(), marked); it != std::sregex_iterator(); ++it) {
    const std::size_t at = std::size_t(it->position(0));
    for (; counted < at; ++counted) line += text[counted] == '\n';
    out.push_back({line, (*it)[1].str(), (*it)[2].str()});
  }
  return out;
}

bool agreesAsWritten(const std::string& written, double measured) {
  const double w = std::strtod(written.c_str(), nullptr);
  if (!std::isfinite(measured)) return false;
  // The place of the last digit written: 1.9e-3 → 1e-4; 0.133 → 1e-3; 27 → 1.
  const std::size_t e = written.find_first_of("eE");
  const std::string mantissa = written.substr(0, e);
  const int exponent = e == std::string::npos ? 0 : std::atoi(written.c_str() + e + 1);
  const std::size_t dot = mantissa.find('.');
  const int decimals = dot == std::string::npos ? 0 : int(mantissa.size() - dot - 1);
  const double last = det::pow(10.0, exponent - decimals);
  return std::abs(measured - w) <= 0.5 * last * (1 + 1e-9);
}

std::vector<std::string> readmeNumberProblems(const std::string& text, const json& summary, const std::string& file) {
  std::vector<std::string> problems;
  for (const ReadmeNumber& n : readmeNumbers(text)) {
    const std::string where = file + " line " + std::to_string(n.line) + ": ";
    const json* value = nullptr;
    try {
      const json::json_pointer ptr(n.pointer);
      if (summary.contains(ptr)) value = &summary.at(ptr);
    } catch (const json::exception&) {
    }
    if (!value || !value->is_number()) {
      problems.push_back(where + n.written + " is marked as measured at \"" + n.pointer +
                         "\", which is not a number of `dynlab run`'s summary.json");
      continue;
    }
    const double measured = value->get<double>();
    if (!agreesAsWritten(n.written, measured))
      problems.push_back(where + n.written + " is written, the run measures " + fmt("%.3g", measured) + " (" + n.pointer + ")");
  }
  return problems;
}

}  // namespace dyn
