#include "arm/kinematics.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "arm/trajectory.h"

namespace costar::arm {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

double squaredDistance(const JointVector& a, const JointVector& b) {
  double sum = 0.0;
  for (int j = 0; j < a.size(); ++j) {
    sum += (a[j] - b[j]) * (a[j] - b[j]);
  }
  return sum;
}

}  // namespace

Kinematics::Kinematics(JointLimits limits) : limits_(std::move(limits)) {
  JointTrajectory::validate(limits_, "Kinematics");
}

void Kinematics::checkSeed(const JointVector& seed, const char* who) const {
  if (seed.size() != jointCount()) {
    throw std::invalid_argument(std::string(who) + ": the seed has " + std::to_string(seed.size()) +
                                " joints, the arm " + std::to_string(jointCount()));
  }
  if (!allFinite(seed)) {
    throw std::invalid_argument(std::string(who) + ": the seed has a non-finite joint angle");
  }
}

void Kinematics::solutionsNear(const world::Pose& flange, const JointVector& seed, IkSolutions& solutions) const {
  inverse(flange, seed, solutions);
  int kept = 0;
  for (int s = 0; s < solutions.size(); ++s) {
    JointVector q = solutions[s];
    bool within = q.size() == limits_.size();
    for (int j = 0; j < q.size() && within; ++j) {
      // The 2*pi-equivalent nearest the seed, moved inside the limits if it is not.
      double angle = q[j] + kTwoPi * std::round((seed[j] - q[j]) / kTwoPi);
      while (angle > limits_.max_position[j]) {
        angle -= kTwoPi;
      }
      while (angle < limits_.min_position[j]) {
        angle += kTwoPi;
      }
      within = angle <= limits_.max_position[j];
      q[j] = angle;
    }
    if (within) {
      solutions[kept++] = q;
    }
  }
  solutions.truncate(kept);
  std::sort(solutions.begin(), solutions.end(), [&seed](const JointVector& a, const JointVector& b) {
    return squaredDistance(a, seed) < squaredDistance(b, seed);
  });
}

std::optional<JointVector> Kinematics::inverseNearest(const world::Pose& flange, const JointVector& seed,
                                                      const Acceptable& acceptable) const {
  checkSeed(seed, "Kinematics::inverseNearest");
  IkSolutions solutions;
  solutionsNear(flange, seed, solutions);
  for (const JointVector& q : solutions) {
    if (!acceptable || acceptable(q)) {
      return q;
    }
  }
  return std::nullopt;
}

}  // namespace costar::arm
