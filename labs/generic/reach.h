// Whether a data lab's task path stays where the mechanism can take its tool, checked when the lab is
// read: each moving segment sampled (about every 2 mm of its path, 8 to 500 samples) and followed by the
// controller's own inverse kinematics (labs/controllers/controller.h) from the lab's start pose, each
// sample from the last one's solution. A point is refused, naming the segment's JSON path and the point,
// when the tool cannot get within 1 µm of it (out of reach: the message gives how near it gets) or when
// the pose that reaches it is singular: the loop's passive joints undetermined (ClosedChain::update) or
// the task Jacobian J_x's smallest singular value below 1e-3 of its largest (the task laws' J_x⁻¹ would
// amplify errors a thousandfold; the tool cannot move along every task axis).
#pragma once
#include <string>
#include <vector>

#include "labs/config.h"
#include "labs/controllers/controller.h"
#include "labs/generic/task_path.h"

namespace dyn::generic {

// Throws InputError at /trajectory/segments/<i>/<move|circle> for the first point out of reach or singular.
void checkReach(const JsonView& trajectory, const TaskPath& path, const MechanismModel<Spatial>& model,
                const std::vector<int>& actuated, const controllers::TaskPoint& tool, const std::vector<std::string>& axis_names,
                const VecN& q0);

}  // namespace dyn::generic
