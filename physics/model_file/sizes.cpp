// A model's size as its text writes it, counted before MuJoCo compiles anything (model_file.h's
// kMaxBodies ...): the text parsed by tinyxml2 (the XML parser MuJoCo itself links), every <include>
// expanded from the checked virtual files (as MuJoCo will expand it, as often as it is written),
// bodies, joints, geoms and equalities counted (URDF: links, joints, visual and collision shapes),
// <default> classes left out (templates, not elements). A text that is not well-formed is left to
// MuJoCo's parser, which says where. Bounded: at most kMaxElements elements are visited, includes
// nest at most kMaxIncludeDepth deep, and tinyxml2 nests elements at most 100 deep.
#include <tinyxml2.h>

#include <cstring>
#include <map>
#include <memory>
#include <string>

#include "physics/model_file/mujoco_call.h"

namespace dyn::model_file::detail {
namespace {

struct Counts {
  long bodies = 0, joints = 0, geoms = 0, equalities = 0, elements = 0;
};

struct Walk {
  Walk(const std::string& p, const mjVFS* v, bool u) : path(p), vfs(v), urdf(u) {}
  const std::string& path;
  const mjVFS* vfs;
  bool urdf;
  Counts n;

  [[noreturn]] void fail(const std::string& what) const { throw ModelFileError(path + ": " + what); }

  std::map<int, std::unique_ptr<tinyxml2::XMLDocument>> parsed;  // by virtual file: each parsed once

  // A virtual file's root element; null if it is not there or not well-formed XML.
  const tinyxml2::XMLElement* root(const char* name) {
    const int at = mj_findFileVFS(vfs, name);
    if (at < 0) return nullptr;
    auto& doc = parsed[at];
    if (!doc) {
      doc = std::make_unique<tinyxml2::XMLDocument>();
      doc->Parse(static_cast<const char*>(vfs->filedata[at]), std::size_t(vfs->filesize[at]));
    }
    return doc->Error() ? nullptr : doc->RootElement();
  }

  // The children of e, as if they stood under an element named `parent`.
  void children(const tinyxml2::XMLElement* e, const char* parent, int depth) {
    for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) element(c, parent, depth);
  }

  void element(const tinyxml2::XMLElement* e, const char* parent, int depth) {
    if (++n.elements > kMaxElements)
      fail("more than " + std::to_string(kMaxElements) + " XML elements with its includes expanded (a model file has a few thousand at most)");
    const char* name = e->Name();
    auto is = [&](const char* a) { return std::strcmp(name, a) == 0; };
    auto under = [&](const char* a) { return std::strcmp(parent, a) == 0; };
    if (is("default")) return;
    if (is("include")) {
      const char* file = e->Attribute("file");
      if (!file) return;  // MuJoCo's parser says so
      if (depth >= kMaxIncludeDepth)
        fail("includes nested deeper than " + std::to_string(kMaxIncludeDepth) + " (at '" + oneLine(file).substr(0, 200) +
             "'; does a file include itself?)");
      if (const tinyxml2::XMLElement* r = root(file)) children(r, parent, depth + 1);
      return;
    }
    if (is("composite"))
      fail("<composite> makes bodies the file does not write out; dynlab reads bodies written in the file (hinge and slide joints)");
    if (urdf) {
      if (is("link")) ++n.bodies;
      if (is("joint") && under("robot")) ++n.joints;
      if (is("visual") || is("collision")) ++n.geoms;
    } else {
      if (is("body")) ++n.bodies;
      if ((is("joint") || is("freejoint")) && under("body")) ++n.joints;
      if (is("geom") && (under("body") || under("worldbody"))) ++n.geoms;
      if (under("equality")) ++n.equalities;
    }
    children(e, name, depth);
  }
};

void atMost(const std::string& path, long count, long limit, const char* what) {
  if (count > limit)
    throw ModelFileError(path + ": " + std::to_string(count) + " " + what + ", more than the " + std::to_string(limit) + " a model file may have");
}

}  // namespace

void checkSizes(const std::string& path, const std::string& text, const mjVFS* vfs) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS || !doc.RootElement()) return;  // MuJoCo's parser says where
  Walk walk(path, vfs, std::strcmp(doc.RootElement()->Name(), "robot") == 0);
  walk.children(doc.RootElement(), doc.RootElement()->Name(), 0);
  const Counts& n = walk.n;
  atMost(path, n.bodies, kMaxBodies, walk.urdf ? "links" : "bodies");
  atMost(path, n.joints, kMaxJoints, "joints");
  atMost(path, n.geoms, kMaxGeoms, walk.urdf ? "visual and collision shapes" : "geoms");
  atMost(path, n.equalities, kMaxEqualities, "equalities");
}

}  // namespace dyn::model_file::detail
