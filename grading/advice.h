// What to change when a test falls short, chosen by the law the submission uses and by why it lost
// points. A metric's "advice" in the lab's metric_docs is one text for every submission, or a list
// of entries, the first whose "when" holds chosen (an entry without "when" is the fallback):
//   "advice": [
//     {"when": {"kind": ["task_pd_gravity", "joint_pd_gravity"]}, "text": "raise kp with kd, or use ..."},
//     {"when": {"kind": "impedance_inverse_dynamics", "gains_off": {"k_imp": "{/target/k}"}},
//      "text": "program the target's stiffness: k_imp = K_des"},
//     {"when": {"scenario": "payload", "above": {"e_final": 0.001}}, "text": "..."},
//     {"text": "the fallback"}]
// "when" holds when all its conditions do:
//   <option>        a submission option's choice, or a list of them (the law in use)
//   scenario        the test's scenario, or a list of them
//   gains_at        {gain: value}: every gain listed is at its value (within 1 %)
//   gains_off       {gain: value}: some gain listed is off its value (by more than 1 %)
//   above / below   {metric: value}: the test's scenario's run measured the metric above / below it
// A value is a number or an expression of numbers and "{/json/pointer}"s of the config (+ − * /,
// parentheses, sqrt): "2*{/target/zeta}*sqrt({/target/k}*{/target/m})". Texts take "{/pointer}" too.
// Both are read with the lab's config, so a malformed entry is the lab's error (InputError naming
// its file and JSON path), found by check-lab before any student sees it.
#pragma once
#include <string>
#include <vector>

#include "labs/config.h"

namespace dyn {

struct AdviceEntry {
  json when = json::object();  // the conditions, values already evaluated to numbers
  std::string text;            // placeholders filled
  std::string path;            // where it is in the lab's JSON (for check-lab's messages)
};

// A metric doc's "advice" (v), read against the lab's config; throws InputError naming the path.
std::vector<AdviceEntry> parseAdvice(const JsonView& v, const JsonView& config);

// What the grader knows when it picks: the graded config (the submission's options and gains
// applied), the test's scenario and the metrics its run measured.
struct AdviceContext {
  const json& config;
  std::string scenario;
  const json& metrics;
};
bool adviceApplies(const AdviceEntry& entry, const AdviceContext& context);
// The first entry that applies ("" when none does).
std::string chooseAdvice(const std::vector<AdviceEntry>& entries, const AdviceContext& context);

// For people reading the handout: every entry, each with its law and scenario ("kind
// task_pd_gravity: …; in payload: …"), joined.
std::string adviceSummary(const std::vector<AdviceEntry>& entries);

// check-lab's look at every advice entry of a lab: it names options, choices, scenarios and gains
// that exist, and no entry tells a student to use the law they already use or names a gain that
// law does not read (unless the text names the law that reads it, as the one to switch to). One
// line per problem ("/metric_docs/e_rms/advice/0: …").
std::vector<std::string> adviceProblems(const json& config, const std::string& file);

// A text's identifier-like words (runs of letters, digits and '_'): how an advice text is read for
// the gains and laws it names.
std::vector<std::string> identifierWords(const std::string& text);

}  // namespace dyn
