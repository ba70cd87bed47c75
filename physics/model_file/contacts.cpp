// Geoms that may collide in MuJoCo: dynlab has no geom-geom contact, so a file with collision geoms
// (almost every published one) loads all the same, and says so once. MuJoCo's copies of the compiled
// model run with contact disabled (model_file.cpp's load), so its cross-check is the same mechanism.
#include <algorithm>
#include <unordered_set>

#include "physics/model_file/mujoco_call.h"

namespace dyn::model_file::detail {

namespace {

std::string named(const mjModel* m, int type, int id, const char* what) {
  const char* n = mj_id2name(m, type, id);
  return n && *n ? std::string(n) : std::string(what) + " #" + std::to_string(id);
}

}  // namespace

void noteContacts(const mjModel* m, std::vector<std::string>& notes) {
  const int flags = m->opt.disableflags;
  if (flags & (mjDSBL_CONTACT | mjDSBL_CONSTRAINT)) return;
  // MuJoCo's filter: different rigid bodies, not parent and child unless one is the world,
  // contype/conaffinity compatible, not excluded.
  const std::unordered_set<int> exclusions(m->exclude_signature, m->exclude_signature + m->nexclude);
  auto excluded = [&](int b1, int b2) {
    return exclusions.count(((b1 + 1) << 16) + b2 + 1) > 0 || exclusions.count(((b2 + 1) << 16) + b1 + 1) > 0;
  };
  const bool filterparent = !(flags & mjDSBL_FILTERPARENT);
  std::vector<bool> involved(std::size_t(m->ngeom), false);
  int first1 = -1, first2 = -1;
  for (int g1 = 0; g1 < m->ngeom; ++g1)
    for (int g2 = g1 + 1; g2 < m->ngeom; ++g2) {
      const int b1 = m->geom_bodyid[g1], b2 = m->geom_bodyid[g2];
      const int w1 = m->body_weldid[b1], w2 = m->body_weldid[b2];
      if (w1 == w2) continue;
      const int p1 = m->body_weldid[m->body_parentid[w1]], p2 = m->body_weldid[m->body_parentid[w2]];
      if (filterparent && w1 != 0 && w2 != 0 && (w1 == p2 || w2 == p1)) continue;
      if (!(m->geom_contype[g1] & m->geom_conaffinity[g2]) && !(m->geom_contype[g2] & m->geom_conaffinity[g1])) continue;
      if (excluded(b1, b2)) continue;
      if (first1 < 0) first1 = g1, first2 = g2;
      involved[std::size_t(g1)] = involved[std::size_t(g2)] = true;
    }
  const long geoms = std::count(involved.begin(), involved.end(), true);
  if (geoms == 0 && m->npair == 0) return;
  std::string what;
  if (geoms > 0)
    what = std::to_string(geoms) + " geoms collide in MuJoCo but not here (e.g. '" + named(m, mjOBJ_GEOM, first1, "geom") + "' and '" +
           named(m, mjOBJ_GEOM, first2, "geom") + "')";
  if (m->npair > 0)
    what += (geoms > 0 ? "; " : "") + std::to_string(m->npair) + " <contact><pair> (e.g. '" + named(m, mjOBJ_PAIR, 0, "pair") +
            "') collide in MuJoCo but not here";
  notes.push_back(what + ": dynlab has no geom–geom contact; the hand engine, Bullet and MuJoCo's cross-check all run without it");
}

}  // namespace dyn::model_file::detail
