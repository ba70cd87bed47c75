// MuJoCo 3 syntax that Debian's MuJoCo 2.2.2 rejects, translated where its meaning is plain, before
// MuJoCo parses (mjcf3.h). Current exporters (onshape-to-robot, Menagerie) write MuJoCo 3; 2.2.2 would
// refuse the whole file over one attribute. Translated, each as MuJoCo 3 defines it:
//  * <connect site1 site2> → <connect body1 body2 anchor>: the sites' bodies, anchor = site1's position
//    in its body. 2.2.2 places body2's anchor where body1's is at the reference pose; MuJoCo 3 ties the
//    two sites, so the two mean the same only when site2 is at site1 there: checked (within 1e-4 of the
//    model's extent, for a CAD export's rounded digits; the gap noted), else refused in one line.
//  * <weld site1 site2> → <weld body1 body2 anchor> (anchor = site2's position in its body, relpose
//    left to the reference pose): the sites' frames must coincide there (position and orientation).
//  * kv and dampratio on <position> (also from a <default> class) → <general> with MuJoCo's affine
//    servo law: gain kp, bias (0, −kp, −kv); dampratio as MuJoCo 3 computes it at compile time,
//    kv = dampratio · 2 √(kp · M_jj / gear²) with M_jj the joint's diagonal inertia at qpos0 (armature
//    included), for an actuator on one hinge or slide joint (other transmissions refused: write kv).
//  * inheritrange on <position> (or from its class) → ctrlrange: the joint's range scaled about its
//    middle (a hinge or slide joint with a range; others refused: write ctrlrange).
//  * MuJoCo 3's autolimits default (true; 2.2.2's is false and refuses a range without `limited`):
//    <compiler autolimits="true"> when the file says nothing and writes such a range. A file 2.2.2
//    reads compiles the same either way.
//  * <size memory> (MuJoCo 3's arena size): left out, 2.2.2 sizes its own.
//  * <option integrator="implicitfast"> (MuJoCo 3's implicit integrator without the Coriolis terms'
//    derivatives) → "implicit": dynlab's engines use their own integrators and its MuJoCo runs Euler.
// The sites' bodies and frames, M and the joints' ranges come from a first compile of the text with those equalities
// left out (MuJoCo resolves the defaults, classes and frames, not dynlab). Everything else 2.2.2's
// schema lacks is refused by mjcf3_schema.cpp in one line naming the file, line and attribute.
#include "physics/model_file/mjcf3.h"
#include "physics/det/det.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "physics/model_file/mujoco_call.h"
#include "physics/model_file/number_text.h"

namespace dyn::model_file::detail {
namespace {

using tinyxml2::XMLElement;

bool is(const XMLElement* e, const char* name) { return std::strcmp(e->Name(), name) == 0; }

std::string num(double x) { return detail::numberText(x, 17); }

std::string shortNum(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", x);
  return b;
}

// The numbers an attribute holds (none when absent or not numbers).
std::vector<double> numbers(const XMLElement* e, const char* attribute) {
  std::vector<double> out;
  const char* s = e->Attribute(attribute);
  if (!s) return out;
  std::istringstream in(s);
  double x;
  while (in >> x) out.push_back(x);
  return out;
}

// A position servo's gains as MuJoCo 3 resolves them: the element's own, else its class's, else the
// classes it inherits from (MuJoCo's defaults: 1 for kp, no damping).
struct Gains {
  bool has_kp = false, has_damping = false, ratio = false, has_inherit = false;
  double kp = 1, damping = 0;  // damping: kv, or the damping ratio when `ratio`
  double inherit = 0;          // inheritrange: the joint's range scaled about its middle as ctrlrange
  // Fills what is still missing from a <position> or <general> element.
  void from(const XMLElement* e) {
    if (is(e, "position")) {
      if (!has_kp && e->Attribute("kp")) has_kp = e->QueryDoubleAttribute("kp", &kp) == tinyxml2::XML_SUCCESS;
      if (!has_damping && e->Attribute("kv")) has_damping = e->QueryDoubleAttribute("kv", &damping) == tinyxml2::XML_SUCCESS;
      if (!has_damping && e->Attribute("dampratio"))
        has_damping = ratio = e->QueryDoubleAttribute("dampratio", &damping) == tinyxml2::XML_SUCCESS;
      if (!has_inherit && e->Attribute("inheritrange"))
        has_inherit = e->QueryDoubleAttribute("inheritrange", &inherit) == tinyxml2::XML_SUCCESS;
    } else if (is(e, "general")) {
      // A class's actuator default is one for all kinds: a <general> gain is a position servo's kp.
      // (Its bias is not read: only kv and dampratio written on a <position> are MuJoCo 3 syntax, and
      // a file without them is left as 2.2.2 reads it.)
      const std::vector<double> gain = numbers(e, "gainprm");
      if (!has_kp && !gain.empty()) has_kp = true, kp = gain[0];
    }
  }
};

// An equality written with sites, parked while the first compile runs (a comment marks its place).
struct Tie {
  XMLElement* element;
  tinyxml2::XMLComment* mark;
};

// A position servo whose damping ratio (kv still to compute) or inheritrange (ctrlrange still to set)
// needs the compiled model: actuator `index`.
struct Pending {
  std::size_t index;
  XMLElement* element;
  double kp, value;  // value: the damping ratio, or the inheritrange scale
};

struct Translation {
  explicit Translation(MjcfDocs& d) : docs(d) {}
  MjcfDocs& docs;
  std::map<std::string, std::pair<XMLElement*, std::string>> classes;  // class → (its <default>, parent class)
  std::vector<XMLElement*> actuators;                                 // in MuJoCo's order
  std::vector<XMLElement*> default_positions, compilers, sizes, sited, options;
  bool autolimits_said = false, range_without_limited = false;
  std::vector<Tie> ties;
  std::vector<Pending> servos, ranges;
  std::vector<std::string> notes;

  void changed(const tinyxml2::XMLNode* e) { docs.docOf(e).changed = true; }

  // Every element, as MuJoCo will see it: defaults and their classes, actuators, equalities, ranges.
  void collect(XMLElement* e, const std::string& cls, bool in_default) {
    docs.children(e, [&](XMLElement* c) {
      std::string inner = cls;
      if (is(c, "default")) {
        const char* name = c->Attribute("class");
        inner = name ? name : "main";
        if (!classes.count(inner)) classes[inner] = {c, in_default ? cls : std::string()};
      }
      if (in_default && is(c, "position")) default_positions.push_back(c);
      if (is(e, "actuator")) actuators.push_back(c);
      // (A file included twice is one document: its equality is parked once.)
      if (is(e, "equality") && (is(c, "connect") || is(c, "weld")) && (c->Attribute("site1") || c->Attribute("site2")) &&
          std::find(sited.begin(), sited.end(), c) == sited.end())
        sited.push_back(c);
      if (is(c, "compiler")) compilers.push_back(c), autolimits_said = autolimits_said || c->Attribute("autolimits");
      if (is(c, "size") && c->Attribute("memory")) sizes.push_back(c);
      if (is(c, "option") && c->Attribute("integrator", "implicitfast")) options.push_back(c);
      static const char* const kRanges[4][2] = {{"range", "limited"}, {"ctrlrange", "ctrllimited"}, {"forcerange", "forcelimited"}, {"actrange", "actlimited"}};
      for (const auto& r : kRanges)
        if (c->Attribute(r[0]) && !c->Attribute(r[1])) range_without_limited = true;
      collect(c, inner, in_default || is(c, "default"));
    });
  }

  Gains resolve(const XMLElement* position) {
    Gains g;
    g.from(position);
    const char* c = position->Attribute("class");
    std::string cls = c ? c : "main";
    for (int guard = 0; guard < 1000 && !cls.empty() && classes.count(cls); ++guard) {
      for (const XMLElement* d = classes[cls].first->FirstChildElement(); d; d = d->NextSiblingElement()) g.from(d);
      cls = classes[cls].second;
    }
    return g;
  }

  // <position> servos with kv or dampratio → <general>; kv and dampratio out of the defaults.
  void servosToGeneral() {
    int translated = 0;
    for (std::size_t i = 0; i < actuators.size(); ++i) {
      XMLElement* a = actuators[i];
      if (!is(a, "position")) continue;
      const Gains g = resolve(a);
      if (g.has_inherit && g.inherit > 0) {
        if (a->Attribute("ctrlrange"))
          throw ModelFileError(docs.where(a) + ": <position> has both ctrlrange and inheritrange (MuJoCo 3 refuses them together too)");
        ranges.push_back({i, a, g.kp, g.inherit});
        changed(a);
      }
      if (a->Attribute("inheritrange")) a->DeleteAttribute("inheritrange"), changed(a);
      if (!g.has_damping) continue;
      a->SetName("general");
      for (const char* gone : {"kp", "kv", "dampratio"}) a->DeleteAttribute(gone);
      a->SetAttribute("dyntype", "none");
      a->SetAttribute("gaintype", "fixed");
      a->SetAttribute("biastype", "affine");
      a->SetAttribute("gainprm", num(g.kp).c_str());
      a->SetAttribute("biasprm", ("0 " + num(-g.kp) + " " + num(g.ratio ? 0.0 : -g.damping)).c_str());
      if (g.ratio) servos.push_back({i, a, g.kp, g.damping});
      changed(a);
      ++translated;
    }
    if (translated) notes.push_back(std::to_string(translated) + " <position> servos with kv or dampratio as <general>");
    for (XMLElement* d : default_positions)
      for (const char* gone : {"kv", "dampratio", "inheritrange"})
        if (d->Attribute(gone)) d->DeleteAttribute(gone), changed(d);
  }

  void plainOnes() {
    if (!autolimits_said && range_without_limited) {
      XMLElement* c = compilers.empty() ? nullptr : compilers[0];
      if (!c) c = docs.root()->InsertFirstChild(docs.docs[0].doc->NewElement("compiler"))->ToElement();
      c->SetAttribute("autolimits", "true");
      changed(c);
      notes.push_back("autolimits=\"true\" (MuJoCo 3's default)");
    }
    for (XMLElement* s : sizes) s->DeleteAttribute("memory"), changed(s), notes.push_back("<size memory> left out (2.2.2 sizes its own)");
    for (XMLElement* o : options)
      o->SetAttribute("integrator", "implicit"), changed(o), notes.push_back("integrator implicitfast read as implicit (MuJoCo's runs here use Euler)");
  }

  // Site-to-site equalities parked for the first compile: a comment in their place.
  void parkTies() {
    for (XMLElement* e : sited) {
      if (!e->Attribute("site1") || !e->Attribute("site2") || e->Attribute("body1") || e->Attribute("body2"))
        throw ModelFileError(docs.where(e) + ": <" + e->Name() +
                             "> names its sides by site1 and site2 (MuJoCo 3) or by body1 and body2 (2.2.2): expected both sites and no body");
      tinyxml2::XMLDocument* doc = e->GetDocument();
      tinyxml2::XMLComment* mark = doc->NewComment(" dynlab: a site-to-site equality ");
      e->Parent()->InsertAfterChild(e, mark);
      doc->NewElement("parked")->InsertEndChild(e);  // unlinked from the tree, still the document's
      ties.push_back({e, mark});
      docs.docOf(e).changed = true;
    }
  }

  void finish(const mjModel* m);
  void placeTie(const mjModel* m, const mjData* d, const Tie& t);
  void setRatio(const mjModel* m, const mjData* d, const Pending& s);
  void setRange(const mjModel* m, const Pending& s);
};

// A body's name for MuJoCo 2.2.2's form of an equality.
std::string bodyName(MjcfDocs& docs, const mjModel* m, int b, const XMLElement* e, const char* site) {
  if (b == 0) return "world";
  const char* n = mj_id2name(m, mjOBJ_BODY, b);
  if (!n || !*n)
    throw ModelFileError(docs.where(e) + ": <" + e->Name() + " " + site + "='" + e->Attribute(site) +
                         "'>: the site's body has no name, which MuJoCo 2.2.2's form of the equality needs (name the body)");
  return n;
}

void Translation::placeTie(const mjModel* m, const mjData* d, const Tie& t) {
  XMLElement* e = t.element;
  const bool weld = is(e, "weld");
  int s[2];
  const char* side[2] = {"site1", "site2"};
  for (int k = 0; k < 2; ++k) {
    s[k] = mj_name2id(m, mjOBJ_SITE, e->Attribute(side[k]));
    if (s[k] < 0) throw ModelFileError(docs.where(e) + ": <" + e->Name() + " " + side[k] + "='" + oneLine(e->Attribute(side[k])).substr(0, 80) + "'>: no site has that name");
  }
  const std::string what = std::string("<") + e->Name() + " site1='" + e->Attribute("site1") + "' site2='" + e->Attribute("site2") + "'>";
  // The sites at the reference pose: apart by `gap`, turned by `angle` (a weld's frames).
  double gap2 = 0, R[9];
  for (int k = 0; k < 3; ++k) { const double dk = d->site_xpos[3 * s[0] + k] - d->site_xpos[3 * s[1] + k]; gap2 += dk * dk; }
  mju_mulMatTMat(R, d->site_xmat + 9 * s[0], d->site_xmat + 9 * s[1], 3, 3, 3);
  const double sine = 0.5 * std::sqrt((R[7] - R[5]) * (R[7] - R[5]) + (R[2] - R[6]) * (R[2] - R[6]) + (R[3] - R[1]) * (R[3] - R[1]));
  const double gap = std::sqrt(gap2), angle = weld ? det::atan2(sine, 0.5 * (R[0] + R[4] + R[8] - 1)) : 0.0;
  const double tolerance = 1e-4 * std::max(1e-3, double(m->stat.extent));
  if (gap > tolerance || angle > 1e-4)
    throw ModelFileError(docs.where(e) + ": " + what + ": the loop is not closed at the reference pose (site2 is " + shortNum(gap) + " m from site1" +
                         (weld ? ", turned " + shortNum(angle) + " rad" : std::string()) +
                         "); Debian's MuJoCo 2.2.2 holds a loop as it is at the reference pose: write the file in its closed pose");
  if (gap > 1e-12 * std::max(1e-3, double(m->stat.extent)) || angle > 1e-12)
    notes.push_back(what + " apart by " + shortNum(gap) + " m" + (weld ? ", " + shortNum(angle) + " rad" : std::string()) +
                    " at the reference pose (rounded digits): held as they are there");
  const int b1 = m->site_bodyid[s[0]], b2 = m->site_bodyid[s[1]];
  const std::string body1 = bodyName(docs, m, b1, e, "site1"), body2 = bodyName(docs, m, b2, e, "site2");
  const mjtNum* p = m->site_pos + 3 * s[weld ? 1 : 0];
  e->DeleteAttribute("site1");
  e->DeleteAttribute("site2");
  e->SetAttribute("body1", body1.c_str());
  e->SetAttribute("body2", body2.c_str());
  e->SetAttribute("anchor", (num(p[0]) + " " + num(p[1]) + " " + num(p[2])).c_str());
  t.mark->Parent()->InsertAfterChild(t.mark, e);
  t.mark->Parent()->DeleteChild(t.mark);
}

void Translation::setRatio(const mjModel* m, const mjData* d, const Pending& s) {
  const int a = int(s.index);
  const int j = m->actuator_trnid[2 * a];
  const double gear = m->actuator_gear[6 * a];
  if (m->actuator_trntype[a] != mjTRN_JOINT || (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE) || gear == 0)
    throw ModelFileError(docs.where(s.element) + ": dampratio on <position>: dynlab translates it for a servo on one hinge or slide joint "
                         "(MuJoCo 3 computes kv from the inertia it drives); write kv instead");
  const int dof = m->jnt_dofadr[j];
  const double inertia = d->qM[m->dof_Madr[dof]] / (gear * gear);
  const double kv = s.value * 2 * std::sqrt(s.kp * inertia);
  s.element->SetAttribute("biasprm", ("0 " + num(-s.kp) + " " + num(-kv)).c_str());
  const char* name = mj_id2name(m, mjOBJ_ACTUATOR, a);
  notes.push_back("dampratio " + shortNum(s.value) + " of actuator '" + (name ? std::string(name) : std::to_string(a).insert(0, 1, '#')) + "' read as kv " + shortNum(kv));
}

// inheritrange as MuJoCo 3 reads it: ctrlrange the joint's range scaled by X about its middle.
void Translation::setRange(const mjModel* m, const Pending& s) {
  const int a = int(s.index), j = m->actuator_trnid[2 * a];
  if (m->actuator_trntype[a] != mjTRN_JOINT || (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE) || !m->jnt_limited[j])
    throw ModelFileError(docs.where(s.element) + ": inheritrange on <position>: dynlab translates it for a servo on one hinge or slide joint "
                         "with a range (MuJoCo 3 takes the range from it); write ctrlrange instead");
  const double mid = 0.5 * (m->jnt_range[2 * j] + m->jnt_range[2 * j + 1]), half = 0.5 * s.value * (m->jnt_range[2 * j + 1] - m->jnt_range[2 * j]);
  s.element->SetAttribute("ctrllimited", "true");
  s.element->SetAttribute("ctrlrange", (num(mid - half) + " " + num(mid + half)).c_str());
}

// After the first compile: the parked equalities in 2.2.2's form, the damping ratios as kv.
void Translation::finish(const mjModel* m) {
  if (std::size_t(m->nu) != actuators.size())
    throw ModelFileError(docs.path + ": MuJoCo compiled " + std::to_string(m->nu) + " actuators where dynlab counted " +
                         std::to_string(actuators.size()) + " (dampratio needs each one's place)");
  mjData* d = nullptr;
  MUJOCO_CALL(docs.path, d = mj_makeData(m));
  if (!d) throw ModelFileError(docs.path + ": MuJoCo could not make its data");
  try {
    MUJOCO_CALL(docs.path, mj_kinematics(m, d); mj_comPos(m, d); mj_crb(m, d));
    for (const Tie& t : ties) changed(t.mark), placeTie(m, d, t);
    for (const Pending& s : servos) changed(s.element), setRatio(m, d, s);
    for (const Pending& s : ranges) changed(s.element), setRange(m, s);
  } catch (...) {
    mj_deleteData(d);
    throw;
  }
  mj_deleteData(d);
}

}  // namespace

std::string Mjcf3::ownLines(const std::string& message) const {
  if (lines.empty()) return message;
  std::string out;
  std::size_t from = 0;
  // "line 9" (a schema error) and "line = 9" (a compiler error).
  for (std::size_t at = message.find("line"); at != std::string::npos; at = message.find("line", at + 4)) {
    std::size_t digits = at + 4;
    while (digits < message.size() && (message[digits] == ' ' || message[digits] == '=')) ++digits;
    std::size_t end = digits;
    while (end < message.size() && std::isdigit(static_cast<unsigned char>(message[end]))) ++end;
    if (end == digits || end - digits > 9) continue;
    const std::size_t n = std::stoul(message.substr(digits, end - digits));
    if (n == 0 || n >= lines.size() || lines[n] == 0) continue;
    out += message.substr(from, digits - from) + std::to_string(lines[n]);
    from = end;
  }
  return out + message.substr(from);
}

void translateMjcf3(const std::string& path, const std::string& text, mjVFS* vfs, const std::function<mjModel*()>& compile, Mjcf3& out) {
  MjcfDocs docs(path, text, vfs);
  if (!docs.mjcf()) return;
  Translation t(docs);
  t.collect(docs.root(), "", false);
  t.servosToGeneral();
  t.plainOnes();
  t.parkTies();
  checkSchema(docs);
  if (std::none_of(docs.docs.begin(), docs.docs.end(), [](const MjcfDocs::Doc& d) { return d.changed; })) return;
  docs.store();
  out.lines = docs.lines;
  if (!t.ties.empty() || !t.servos.empty() || !t.ranges.empty()) {
    mjModel* m = compile();
    try {
      t.finish(m);
    } catch (...) {
      mj_deleteModel(m);
      throw;
    }
    mj_deleteModel(m);
    docs.store();
    out.lines = docs.lines;
  }
  out.notes = "MuJoCo 3 syntax translated for Debian's MuJoCo 2.2.2";
  if (!t.ties.empty()) out.notes += "; site-to-site equalities as body1/body2/anchor: " + std::to_string(t.ties.size());
  for (const std::string& n : t.notes) out.notes += "; " + n;
}

}  // namespace dyn::model_file::detail
