// Advice chosen by the law in use and why a test lost points; see advice.h.
#include "grading/advice.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "grading/metric_doc.h"
#include "labs/submission.h"

namespace dyn {
namespace {

constexpr double kSameValue = 0.01;  // relative: a gain within 1 % of a value is at it

// A small expression of numbers: + − * /, parentheses, sqrt(...). Returns NaN when malformed.
struct Expression {
  const std::string& s;
  std::size_t i = 0;
  int depth = 0;  // nested parentheses and signs: a hostile "((((…" is refused, not a stack overflow
  void space() {
    while (i < s.size() && s[i] == ' ') ++i;
  }
  bool eat(char c) {
    space();
    if (i < s.size() && s[i] == c) return ++i, true;
    return false;
  }
  double primary() {
    space();
    if (++depth > 64) return NAN;
    const double v = term();
    --depth;
    return v;
  }
  double term() {
    if (s.compare(i, 4, "sqrt") == 0) {
      i += 4;
      if (!eat('(')) return NAN;
      const double v = sum();
      return eat(')') ? std::sqrt(v) : NAN;
    }
    if (eat('(')) {
      const double v = sum();
      return eat(')') ? v : NAN;
    }
    if (eat('-')) return -primary();
    const char* start = s.c_str() + i;
    char* end = nullptr;
    const double v = std::strtod(start, &end);
    if (end == start) return NAN;
    i += std::size_t(end - start);
    return v;
  }
  double product() {
    double v = primary();
    for (;;) {
      if (eat('*')) v *= primary();
      else if (eat('/')) v /= primary();
      else return v;
    }
  }
  double sum() {
    double v = product();
    for (;;) {
      if (eat('+')) v += product();
      else if (eat('-')) v -= product();
      else return v;
    }
  }
};

double valueOf(const JsonView& v, const JsonView& config) {
  if (v.raw().is_number()) return v.number();
  const std::string expected = "expected a number, or an expression of numbers and \"{/json/pointer}\"s such as \"2*{/target/zeta}\"";
  if (!v.raw().is_string()) v.fail(expected);
  const std::string text = fillFromConfig(v.string(), config, v.path());
  Expression e{text};
  const double x = e.sum();
  e.space();
  if (!std::isfinite(x) || e.i != text.size()) v.fail(expected + ", got \"" + text + "\"");
  return x;
}

// {name: value}: every value evaluated; names checked by `known` (a gain of the lab's).
json namedValues(const JsonView& v, const JsonView& config, bool gains) {
  v.requireObject();
  json out = json::object();
  for (const auto& [name, _] : v.raw().items()) {
    if (gains && !config["gains"].raw().contains(name)) v[name].fail("expected a gain of the lab's \"gains\", got \"" + name + "\"");
    out[name] = valueOf(v[name], config);
  }
  return out;
}

// One choice or a list of them, each among `allowed`.
json choicesOf(const JsonView& v, const json& allowed, const std::string& what) {
  json list = v.raw().is_array() ? v.raw() : json::array({v.raw()});
  for (std::size_t i = 0; i < list.size(); ++i) {
    const JsonView c = v.raw().is_array() ? v.at(i) : v;
    const std::string name = c.string();
    bool ok = false;
    for (const auto& a : allowed) ok = ok || a == name;
    if (!ok) c.fail("expected " + what + " (" + allowed.dump() + "), got \"" + name + "\"");
  }
  return list;
}

AdviceEntry parseEntry(const JsonView& e, const JsonView& config) {
  AdviceEntry out;
  out.path = e.path();
  if (e.raw().is_string()) {
    out.text = fillFromConfig(e.string(), config, e.path());
    return out;
  }
  e.onlyKeys({"when", "text"});
  out.text = fillFromConfig(e["text"].string(), config, e["text"].path());
  if (!e.has("when")) return out;
  const JsonView w = e["when"];
  w.requireObject();
  const json options = config.raw().value("submission_options", json::object());
  json scenarios = json::array();
  if (config.raw().contains("rubric") && config.raw()["rubric"].contains("scenarios"))
    for (const auto& [name, _] : config.raw()["rubric"]["scenarios"].items()) scenarios.push_back(name);
  for (const auto& [key, _] : w.raw().items()) {
    if (options.contains(key)) out.when[key] = choicesOf(w[key], options[key].at("choices"), "a choice of the option " + key);
    else if (key == "scenario") out.when[key] = choicesOf(w[key], scenarios, "a scenario of the rubric");
    else if (key == "gains_at" || key == "gains_off") out.when[key] = namedValues(w[key], config, true);
    else if (key == "above" || key == "below") out.when[key] = namedValues(w[key], config, false);
    else {
      std::string list;
      for (const auto& [o, __] : options.items()) list += o + ", ";
      w[key].fail("expected a condition: " + list + "scenario, gains_at, gains_off, above or below; got \"" + key + "\"");
    }
  }
  return out;
}

bool near(double a, double b) { return std::abs(a - b) <= kSameValue * std::max(std::abs(b), 1e-12); }

double gainOf(const json& config, const std::string& g) {
  const json& v = config.at("gains").at(g);
  return v.is_object() ? v.at("value").get<double>() : v.get<double>();
}

}  // namespace

std::vector<AdviceEntry> parseAdvice(const JsonView& v, const JsonView& config) {
  if (v.raw().is_string()) return {parseEntry(v, config)};
  if (!v.raw().is_array()) v.fail("expected a text, or a list of {\"when\": {...}, \"text\": \"...\"}");
  std::vector<AdviceEntry> out;
  for (std::size_t i = 0, n = v.size(1, 64); i < n; ++i) out.push_back(parseEntry(v.at(i), config));
  return out;
}

bool adviceApplies(const AdviceEntry& entry, const AdviceContext& c) {
  const json options = c.config.value("submission_options", json::object());
  for (const auto& [key, want] : entry.when.items()) {
    // want by name: clang 14 (emscripten's, app/web) cannot capture a structured binding.
    const auto in = [&want = want](const std::string& x) {
      for (const auto& w : want)
        if (w == x) return true;
      return false;
    };
    if (options.contains(key)) {
      if (!in(c.config.at(json::json_pointer(options[key].at("target").get<std::string>())).get<std::string>())) return false;
    } else if (key == "scenario") {
      if (!in(c.scenario)) return false;
    } else if (key == "gains_at" || key == "gains_off") {
      bool all_at = true;
      for (const auto& [g, v] : want.items()) all_at = all_at && near(gainOf(c.config, g), v.get<double>());
      if (key == "gains_at" ? !all_at : all_at) return false;
    } else {  // above / below: a metric the run did not measure (or NaN) holds neither
      for (const auto& [m, v] : want.items()) {
        if (!c.metrics.is_object() || !c.metrics.contains(m) || !c.metrics[m].is_number()) return false;
        const double x = c.metrics[m].get<double>();
        if (!(key == "above" ? x > v.get<double>() : x < v.get<double>())) return false;
      }
    }
  }
  return true;
}

std::string chooseAdvice(const std::vector<AdviceEntry>& entries, const AdviceContext& context) {
  for (const auto& e : entries)
    if (adviceApplies(e, context)) return e.text;
  return "";
}

std::string adviceSummary(const std::vector<AdviceEntry>& entries) {
  std::string out;
  for (const auto& e : entries) {
    // The law first, then the scenario, then what the gains or the run must show.
    std::string law, rest;
    for (const auto& [key, want] : e.when.items()) {
      std::string part;
      const bool measured = key == "gains_at" || key == "gains_off" || key == "above" || key == "below";
      if (measured) {
        const std::string op = key == "gains_at" ? " = " : key == "gains_off" ? " ≠ " : key == "above" ? " > " : " < ";
        char number[32];
        for (const auto& [n, v] : want.items()) {
          std::snprintf(number, sizeof number, "%.4g", v.get<double>());
          part += (part.empty() ? "" : key == "gains_off" ? " or " : " and ") + n + op + number;
        }
      } else {
        for (const auto& w : want) part += (part.empty() ? "" : " or ") + w.get<std::string>();
        part = (key == "scenario" ? "in " : key + " ") + part;
      }
      std::string& to = measured || key == "scenario" ? rest : law;
      if (key == "scenario") rest = part + (rest.empty() ? "" : ", " + rest);
      else to += (to.empty() ? "" : ", ") + part;
    }
    const std::string when = law + (law.empty() || rest.empty() ? "" : ", ") + rest;
    out += (out.empty() ? "" : "; ") + (when.empty() ? (entries.size() > 1 ? "otherwise: " : "") : when + ": ") + e.text;
  }
  return out;
}

std::vector<std::string> adviceProblems(const json& config, const std::string& file) {
  std::vector<std::string> problems;
  if (!config.contains("metric_docs")) return problems;
  const JsonView view(config, file);
  const json options = config.value("submission_options", json::object());
  // Every combination of the options' choices: the laws a submission can select.
  std::vector<json> laws{config};
  for (const auto& [key, o] : options.items()) {
    std::vector<json> more;
    for (const json& l : laws)
      for (const auto& c : o.at("choices")) {
        json x = l;
        x[json::json_pointer(o.at("target").get<std::string>())] = c;
        more.push_back(x);
      }
    laws = more;
  }
  const auto chosen = [&](const json& law, const std::string& key) {
    return law.at(json::json_pointer(options[key].at("target").get<std::string>())).get<std::string>();
  };
  std::set<std::string> reported;  // an entry's problem once, for the first law it fails under
  for (const auto& [metric, doc] : config["metric_docs"].items()) {
    if (!doc.contains("advice")) continue;
    std::vector<AdviceEntry> entries;
    try {
      entries = parseAdvice(view["metric_docs"][metric]["advice"], view);
    } catch (const InputError& e) {
      problems.push_back(e.path() + ": " + e.expected());
      continue;
    }
    for (const json& law : laws) {
      bool covered = false;  // some entry speaks to this law whatever the run
      for (const AdviceEntry& e : entries) {
        bool applies = true, unconditional = true;
        for (const auto& [key, want] : e.when.items()) {
          if (!options.contains(key)) {
            unconditional = false;
            continue;
          }
          bool in = false;
          for (const auto& w : want) in = in || w == chosen(law, key);
          applies = applies && in;
        }
        if (!applies) continue;
        covered = covered || unconditional;
        std::string which;
        for (const auto& [key, _] : options.items()) which += (which.empty() ? "" : ", ") + key + " " + chosen(law, key);
        // The laws the text names: a choice with '_' in it, or any choice right after its option's name.
        const std::vector<std::string> ws = identifierWords(e.text);
        std::vector<json> named;
        for (std::size_t i = 0; i < ws.size(); ++i)
          for (const auto& [key, o] : options.items())
            for (const auto& c : o.at("choices"))
              if (ws[i] == c && (ws[i].find('_') != std::string::npos || (i > 0 && ws[i - 1] == key))) {
                if (chosen(law, key) == ws[i] && reported.insert(e.path + " law " + ws[i]).second)
                  problems.push_back(e.path + ": tells a submission with " + which + " to use " + key + " " + ws[i] + ", the law it uses");
                json other = law;
                other[json::json_pointer(o.at("target").get<std::string>())] = c;
                named.push_back(other);
              }
        const std::set<std::string> read = gainsRead(law);
        std::set<std::string> gains_named;
        for (const auto& w : ws)
          if (config["gains"].contains(w)) gains_named.insert(w);
        for (const char* k : {"gains_at", "gains_off"})
          if (e.when.contains(k))
            for (const auto& [g, _] : e.when[k].items()) gains_named.insert(g);
        for (const std::string& g : gains_named) {
          bool ok = read.count(g) > 0;
          for (const json& other : named) ok = ok || gainsRead(other).count(g) > 0;
          if (!ok && reported.insert(e.path + " gain " + g).second) problems.push_back(e.path + ": names the gain " + g + ", which " + (which.empty() ? "the lab" : which) + " does not read");
        }
      }
      if (!covered && !options.empty()) {
        std::string which;
        for (const auto& [key, _] : options.items()) which += (which.empty() ? "" : ", ") + key + " " + chosen(law, key);
        problems.push_back("/metric_docs/" + metric + "/advice: no entry for " + which + " (an entry whose \"when\" names only options, or none)");
      }
    }
  }
  // One line per problem: an entry that fails for several laws says so once.
  std::vector<std::string> unique;
  for (const auto& p : problems)
    if (std::find(unique.begin(), unique.end(), p) == unique.end()) unique.push_back(p);
  return unique;
}

std::vector<std::string> identifierWords(const std::string& text) {
  std::vector<std::string> out;
  std::string w;
  for (char c : text + " ") {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '_') w += c;
    else if (!w.empty()) out.push_back(w), w.clear();
  }
  return out;
}

}  // namespace dyn
