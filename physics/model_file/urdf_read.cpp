// A URDF's visuals, discardvisual and <mimic> elements read from its parsed elements (urdf_read.h).
#include "physics/model_file/urdf_read.h"

#include <tinyxml2.h>

#include <cstring>

namespace dyn::model_file::detail {
namespace {

struct Reader {
  UrdfFacts facts;
  std::set<std::string> elsewhere;  // file names written outside every <visual>

  // e and its descendants (tinyxml2 nests elements at most 100 deep, so the recursion is bounded).
  void element(const tinyxml2::XMLElement* e, bool in_visual) {
    const char* name = e->Name();
    if (std::strcmp(name, "mimic") == 0) ++facts.mimics;
    in_visual = in_visual || std::strcmp(name, "visual") == 0;
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a; a = a->Next())
      if (std::strncmp(a->Name(), "file", 4) == 0 && *a->Value()) (in_visual ? facts.visual_only : elsewhere).insert(a->Value());
    for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) element(c, in_visual);
  }
};

// MuJoCo's URDF reader reads <robot><mujoco><compiler …/> as MJCF's compiler (discardvisual "true" or "false").
bool keepsVisuals(const tinyxml2::XMLElement* robot) {
  for (const tinyxml2::XMLElement* m = robot->FirstChildElement("mujoco"); m; m = m->NextSiblingElement("mujoco"))
    for (const tinyxml2::XMLElement* c = m->FirstChildElement("compiler"); c; c = c->NextSiblingElement("compiler"))
      if (const char* d = c->Attribute("discardvisual"); d && std::strcmp(d, "false") == 0) return true;
  return false;
}

}  // namespace

UrdfFacts readUrdfFacts(const std::string& text) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS || !doc.RootElement()) return {};
  Reader r;
  r.facts.well_formed = true;
  r.element(doc.RootElement(), false);
  // A name also written outside the visuals (the collision's mesh) is read as any file is.
  for (const std::string& n : r.elsewhere) r.facts.visual_only.erase(n);
  r.facts.keeps_visuals = keepsVisuals(doc.RootElement());
  return r.facts;
}

}  // namespace dyn::model_file::detail
