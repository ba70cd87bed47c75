// A reference path as data: see task_path.h.
#include "labs/generic/task_path.h"

#include <algorithm>
#include <cmath>

#include "physics/det/det.h"

namespace dyn::generic {
namespace {

// s, s', s'' of the quintic timing at τ = (t − t0)/T, in time units.
void quintic(double t, double t0, double T, double& s, double& sd, double& sdd) {
  const double tau = std::clamp((t - t0) / T, 0.0, 1.0);
  const double t2 = tau * tau, t3 = t2 * tau;
  s = t3 * (10.0 - 15.0 * tau + 6.0 * t2);
  sd = 30.0 * t2 * (1.0 - tau) * (1.0 - tau) / T;
  sdd = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau) / (T * T);
}

VecN point(const JsonView& j, int dims, double max) {
  j.size(std::size_t(dims), std::size_t(dims));
  VecN p(dims);
  for (int i = 0; i < dims; ++i) p[i] = j.at(std::size_t(i)).inRange(-max, max);
  return p;
}

}  // namespace

bool TaskPath::isJointSpace(const JsonView& j) {
  return j.has("space") && j["space"].oneOf({"task", "joint"}) == "joint";
}

TaskPath::TaskPath(const JsonView& j, const VecN& start, double max) : start_(start), joint_(isJointSpace(j)) {
  j.onlyKeys({"space", "segments"});
  const int dims = int(start.size());
  const JsonView list = j["segments"];
  const std::size_t count = list.size(1, 64);
  VecN here = start;
  for (std::size_t i = 0; i < count; ++i) {
    const JsonView s = list.at(i);
    Segment seg{Segment::Kind::Hold, end_, 0, here, here};
    if (s.has("move")) {
      s.onlyKeys({"move", "time"});
      seg.kind = Segment::Kind::Move;
      seg.to = point(s["move"], dims, max);
      seg.T = s["time"].inRange(1e-3, 1e4);
    } else if (joint_ && s.has("move_deg")) {
      s.onlyKeys({"move_deg", "time"});
      seg.kind = Segment::Kind::Move;
      seg.to = point(s["move_deg"], dims, max * 180.0 / M_PI) * (M_PI / 180.0);
      seg.T = s["time"].inRange(1e-3, 1e4);
    } else if (s.has("hold")) {
      s.onlyKeys({"hold"});
      seg.T = s["hold"].inRange(0, 1e4);
    } else if (s.has("circle") && !joint_) {
      s.onlyKeys({"circle", "turns", "time"});
      if (dims != 2) s["circle"].fail("a circle needs exactly two task axes");
      seg.kind = Segment::Kind::Circle;
      seg.to = point(s["circle"], dims, max);
      seg.T = s["time"].inRange(1e-3, 1e4);
      seg.sweep = 2.0 * M_PI * s["turns"].inRange(-100, 100);
      const VecN r = here - seg.to;
      seg.radius = r.norm();
      if (seg.radius < 1e-6) s["circle"].fail("expected a centre away from the path's current point");
      seg.psi0 = det::atan2(r[1], r[0]);
      // Where the circle ends.
      const double psi = seg.psi0 + seg.sweep;
      here = seg.to + seg.radius * VecN((VecN(2) << det::cos(psi), det::sin(psi)).finished());
    } else if (joint_) {
      s.fail("expected a joint segment {\"move_deg\": [...], \"time\": T}, {\"move\": [...], \"time\": T} or {\"hold\": T}");
    } else {
      s.fail("expected a segment {\"move\": [...], \"time\": T}, {\"hold\": T} or {\"circle\": [cx, cz], \"turns\": n, \"time\": T}");
    }
    if (seg.kind == Segment::Kind::Move) here = seg.to;
    end_ += seg.T;
    segments_.push_back(seg);
  }
}

void TaskPath::at(double t, VecN& x, VecN& xd, VecN& xdd) const {
  const int d = int(start_.size());
  x = start_, xd = VecN::Zero(d), xdd = VecN::Zero(d);
  for (const Segment& seg : segments_) {
    if (t < seg.t0) break;
    double s, sd, sdd;
    if (seg.T > 0) quintic(t, seg.t0, seg.T, s, sd, sdd);
    else s = 1, sd = sdd = 0;
    switch (seg.kind) {
      case Segment::Kind::Hold:
        x = seg.from, xd.setZero(), xdd.setZero();
        break;
      case Segment::Kind::Move: {
        const VecN delta = seg.to - seg.from;
        x = seg.from + s * delta, xd = sd * delta, xdd = sdd * delta;
        break;
      }
      case Segment::Kind::Circle: {
        // x = c + r (cos ψ, sin ψ), ψ = ψ0 + sweep s.
        const double psi = seg.psi0 + seg.sweep * s, w = seg.sweep * sd, a = seg.sweep * sdd;
        const double c = det::cos(psi), sn = det::sin(psi), r = seg.radius;
        x = seg.to, x[0] += r * c, x[1] += r * sn;
        xd[0] = -r * sn * w, xd[1] = r * c * w;
        xdd[0] = -r * (c * w * w + sn * a), xdd[1] = r * (-sn * w * w + c * a);
        break;
      }
    }
  }
}

}  // namespace dyn::generic
