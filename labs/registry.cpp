// The lab registry: labs add themselves at static-initialisation time (DYNLAB_REGISTER_LAB).
#include <algorithm>
#include <cstdlib>

#include "labs/lab.h"
#include "labs/numbers.h"

#ifndef DYNLAB_SOURCE_DIR
#define DYNLAB_SOURCE_DIR "."
#endif

namespace dyn {

std::list<LabEntry>& labRegistry() {
  static std::list<LabEntry> entries;
  return entries;
}

bool registerLab(LabEntry entry) {
  if (findLab(entry.name)) return false;
  auto& r = labRegistry();
  const auto at = std::find_if(r.begin(), r.end(), [&](const LabEntry& e) { return entry.name < e.name; });
  r.insert(at, std::move(entry));
  return true;
}

bool unregisterLab(const std::string& name) {
  auto& r = labRegistry();
  const auto it = std::find_if(r.begin(), r.end(), [&](const LabEntry& e) { return e.name == name; });
  if (it == r.end()) return false;
  r.erase(it);
  return true;
}

const LabEntry* findLab(const std::string& name) {
  for (const auto& e : labRegistry())
    if (e.name == name) return &e;
  return nullptr;
}

std::string labsRoot() {
  const char* home = std::getenv("DYNLAB_HOME");
  return std::string(home && *home ? home : DYNLAB_SOURCE_DIR) + "/labs";
}

std::string labFolder(const std::string& name) {
  const LabEntry* e = findLab(name);
  return e && !e->folder.empty() ? e->folder : labsRoot() + "/" + name;
}

std::string defaultConfigPath(const std::string& name) { return labFolder(name) + "/" + name + ".json"; }

std::string stoppedSentence(const std::string& failure, double t) {
  if (failure.rfind("stopped: ", 0) == 0) return failure;
  return "unstable: " + failure + " at t = " + fmt("%.4g", t) + " s";
}

}  // namespace dyn
