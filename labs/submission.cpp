// Applying a submission's gains and options to a lab config; see submission.h.
#include "labs/submission.h"

#include <algorithm>
#include <cctype>
#include <sstream>

namespace dyn {

json applySubmission(const json& config, const JsonView& sub, const std::string& lab, bool strict) {
  sub.requireObject();
  json out = config;
  const json options = config.value("submission_options", json::object());
  // Top-level keys: lab, gains, answers and the declared options; nothing else.
  for (const auto& [key, _] : sub.raw().items()) {
    if (key == "lab" || key == "gains" || key == "answers" || options.contains(key)) continue;
    std::string list = "\"lab\", \"gains\", \"answers\"";
    for (const auto& [o, __] : options.items()) list += ", \"" + o + "\"";
    sub[key].fail("unknown key \"" + key + "\" (expected one of: " + list + ")");
  }
  if (strict || sub.has("lab")) {
    const std::string named = sub["lab"].string();
    if (named != lab) sub["lab"].fail("expected \"" + lab + "\", got \"" + named + "\"");
  }
  // Gains: declared names only, finite numbers within the declared bounds.
  const json& declared = config.at("gains");
  if (strict || sub.has("gains")) {
    const JsonView gains = sub["gains"];
    gains.requireObject();
    for (const auto& [name, value] : gains.raw().items()) {
      if (!declared.contains(name)) {
        std::string list;
        for (const auto& [d, _] : declared.items()) list += std::string(list.empty() ? "" : ", ") + d;
        gains[name].fail("unknown gain \"" + name + "\" (this lab's gains: " + list + ")");
      }
      const double lo = declared[name].at("min").get<double>(), hi = declared[name].at("max").get<double>();
      out["gains"][name]["value"] = gains[name].inRange(lo, hi);
    }
    if (strict)
      for (const auto& [name, _] : declared.items())
        if (!gains.has(name)) gains[name];  // throws "missing key"
  }
  // Options: one of the declared choices, written to the declared target.
  for (const auto& [key, decl] : options.items()) {
    if (!sub.has(key)) continue;
    std::string value;
    const auto& choices = decl.at("choices");
    bool ok = false;
    for (const auto& c : choices) ok = ok || (sub[key].raw().is_string() && sub[key].raw() == c);
    if (!ok) {
      std::string list;
      for (const auto& c : choices) list += std::string(list.empty() ? "" : ", ") + c.dump();
      sub[key].fail("expected one of " + list + ", got " + sub[key].raw().dump());
    }
    out[json::json_pointer(decl.at("target").get<std::string>())] = sub[key].raw();
  }
  submissionAnswers(sub);
  return out;
}

json submissionAnswers(const JsonView& sub) {
  if (!sub.has("answers")) return json::object();
  const JsonView answers = sub["answers"];
  answers.requireObject();
  if (answers.raw().size() > kMaxAnswers)
    answers.fail("expected at most " + std::to_string(kMaxAnswers) + " answers, got " + std::to_string(answers.raw().size()));
  for (const auto& [key, _] : answers.raw().items()) {
    bool plain = !key.empty() && key.size() <= 40;
    for (unsigned char c : key) plain = plain && (std::isalnum(c) || c == '_' || c == '-' || c == '.') && c < 0x80;
    if (!plain) answers[key].fail("expected an answer's name of 1–40 letters, digits, '_', '-' or '.'");
    const std::string text = answers[key].string();
    if (text.size() > kMaxAnswerBytes)
      answers[key].fail("expected an answer of at most " + std::to_string(kMaxAnswerBytes) + " bytes, got " +
                        std::to_string(text.size()));
  }
  return answers.raw();
}

void checkSubmissionOptions(const JsonView& config) {
  if (!config.has("submission_options")) return;
  const JsonView options = config["submission_options"];
  options.requireObject();
  for (const auto& [key, _] : options.raw().items()) {
    const JsonView o = options[key];
    if (key == "lab" || key == "gains") o.fail("expected an option name other than \"lab\" and \"gains\"");
    o.onlyKeys({"target", "choices", "doc", "reads"});
    const std::string target = o["target"].string();
    bool found = false;
    try {
      const json::json_pointer ptr(target);
      found = !target.empty() && config.raw().contains(ptr) && config.raw().at(ptr).is_string();
    } catch (const json::exception&) {
    }
    if (!found) o["target"].fail("expected a JSON pointer to a string in the config, such as \"/controller/force_law\", got \"" + target + "\"");
    for (std::size_t i = 0, n = o["choices"].size(1, 64); i < n; ++i) o["choices"].at(i).string();
    if (o.has("doc")) o["doc"].string();
    if (o.has("reads")) {
      // {"choice": ["gain", ...]}: the gains that depend on this option, those each choice reads.
      const JsonView reads = o["reads"];
      reads.requireObject();
      for (const auto& [choice, gains] : reads.raw().items()) {
        bool known = false;
        for (const auto& c : o["choices"].raw()) known = known || c == choice;
        if (!known) reads[choice].fail("expected a choice of this option (" + o["choices"].raw().dump() + "), got \"" + choice + "\"");
        for (std::size_t i = 0, n = reads[choice].size(0, 64); i < n; ++i) {
          const std::string g = reads[choice].at(i).string();
          if (!config.has("gains") || !config["gains"].raw().contains(g)) reads[choice].at(i).fail("expected a gain of the lab's \"gains\", got \"" + g + "\"");
        }
      }
    }
  }
}

std::set<std::string> gainsRead(const json& config) {
  std::set<std::string> read;
  const json gains = config.value("gains", json::object()), options = config.value("submission_options", json::object());
  for (const auto& [g, _] : gains.items()) read.insert(g);
  for (const auto& [key, o] : options.items()) {
    if (!o.contains("reads")) continue;
    const json chosen = config.at(json::json_pointer(o.at("target").get<std::string>()));
    const json none = json::array();
    const json& mine = chosen.is_string() && o["reads"].contains(chosen.get<std::string>()) ? o["reads"][chosen.get<std::string>()] : none;
    // A gain some choice lists is read only when the chosen one lists it too.
    for (const auto& [choice, gains] : o["reads"].items())
      for (const auto& g : gains)
        if (std::find(mine.begin(), mine.end(), g) == mine.end()) read.erase(g.get<std::string>());
  }
  return read;
}

json submissionSchema(const json& config, const std::string& lab) {
  json gains = {{"type", "object"}, {"additionalProperties", false}, {"properties", json::object()},
                {"required", json::array()}};
  for (const auto& [name, d] : config.at("gains").items()) {
    gains["properties"][name] = {{"type", "number"},
                                 {"minimum", d.at("min")},
                                 {"maximum", d.at("max")},
                                 {"default", d.at("value")},
                                 {"description", d.value("doc", "") + " [" + d.value("unit", "") + "]"}};
    gains["required"].push_back(name);
  }
  json schema = {{"$schema", "https://json-schema.org/draft/2020-12/schema"},
                 {"title", "dynlab submission: " + lab},
                 {"type", "object"},
                 {"additionalProperties", false},
                 {"required", {"lab", "gains"}},
                 {"properties", {{"lab", {{"const", lab}}}, {"gains", gains}}}};
  schema["properties"]["answers"] = {
      {"type", "object"},
      {"maxProperties", kMaxAnswers},
      {"propertyNames", {{"pattern", "^[A-Za-z0-9_.-]{1,40}$"}}},
      {"additionalProperties", {{"type", "string"}, {"maxLength", kMaxAnswerBytes}}},
      {"description", "free-text answers to the handout's questions, for the course staff (not graded)"}};
  const json options = config.value("submission_options", json::object());
  for (const auto& [key, d] : options.items())
    schema["properties"][key] = {{"enum", d.at("choices")}, {"description", d.value("doc", "")}};
  return schema;
}

}  // namespace dyn
