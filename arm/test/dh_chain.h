#pragma once
// A standard-DH six-joint arm (the UR5's published table) as a serial chain, for the tests that
// hold the general chain solver against the UR closed form.

#include "arm/chain_kinematics.h"
#include "arm/ur5_kinematics.h"

namespace costar::arm::testing {

/// Joint i's frame is row i-1's Tz(d) Tx(a) Rx(alpha) after joint i-1's rotation; the flange is
/// the last row's.
inline ChainGeometry chainFromDh(const DhParameters& dh) {
  const auto row = [&dh](int i) {
    world::Pose pose = world::Pose::Identity();
    pose.translate(Eigen::Vector3d(dh.a[i], 0, dh.d[i]));
    pose.rotate(Eigen::AngleAxisd(dh.alpha[i], Eigen::Vector3d::UnitX()));
    return pose;
  };
  ChainGeometry chain;
  for (int i = 0; i < 6; ++i) {
    chain.joints.push_back({i == 0 ? world::Pose::Identity() : row(i - 1), Eigen::Vector3d::UnitZ()});
  }
  chain.flange = row(5);
  return chain;
}

}  // namespace costar::arm::testing
