// Stages 5 and 6: setCanonicalOrientation and persistenceUpdate (Algorithm 1), on synthetic
// poses.

#include "perception/persistence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <tuple>

#include "core/paths.h"
#include "perception/canonical_orientation.h"

namespace costar::perception {
namespace {

const std::vector<world::ObjectClass>& classes() {
  static const std::vector<world::ObjectClass> loaded = world::loadObjectClasses(dataRoot() / "data/objects");
  return loaded;
}

const world::ObjectClass& objectClass(const std::string& name) {
  for (const auto& c : classes()) {
    if (c.name == name) {
      return c;
    }
  }
  throw std::runtime_error(name);
}

Detection detection(const std::string& object_class, double x, double y, double yaw = 0.0) {
  Detection d;
  d.object_class = object_class;
  d.pose = world::poseFromXyzRpy(x, y, object_class == "node" ? 0.025 : 0.0125, 0, 0, yaw);
  d.confidence = 0.99;
  return d;
}

std::vector<std::string> names(const std::vector<TrackedObject>& objects) {
  std::vector<std::string> out;
  for (const auto& object : objects) {
    out.push_back(object.name);
  }
  return out;
}

// --- setCanonicalOrientation -------------------------------------------------------------------

TEST(CanonicalOrientation, ANodeGetsZUpAndXNearestTheWorldsX) {
  const world::ObjectClass& node = objectClass("node");
  std::mt19937 random(2);
  std::uniform_real_distribution<double> yaw(-M_PI, M_PI);
  for (int trial = 0; trial < 50; ++trial) {
    const double angle = yaw(random);
    // Any of the 24 equivalent frames of the same physical cube.
    const Eigen::Matrix3d symmetric = node.symmetries[static_cast<std::size_t>(trial % 24)];
    world::Pose pose = world::poseFromXyzRpy(0.5, 0.1, 0.025, 0, 0, angle);
    pose.linear() = pose.linear() * symmetric;
    const CanonicalPose canonical = setCanonicalOrientation(pose, node);
    const Eigen::Matrix3d r = canonical.pose.linear();
    EXPECT_GT(r.col(2).z(), 0.9999);                     // z up
    EXPECT_GE(r.col(0).x(), std::cos(M_PI / 4) - 1e-9);  // x within 45 degrees of the world's x
    EXPECT_TRUE(canonical.pose.translation().isApprox(pose.translation()));
    // The same physical cube: the canonical frame is one of its symmetric frames.
    EXPECT_LT(symmetricRotationDistance(r, pose.linear(), node), 1e-6);
  }
}

TEST(CanonicalOrientation, TheSameCubeAlwaysGetsTheSameFrame) {
  const world::ObjectClass& node = objectClass("node");
  const world::Pose base = world::poseFromXyzRpy(0.4, -0.2, 0.025, 0.02, -0.01, 0.7);
  const Eigen::Matrix3d expected = setCanonicalOrientation(base, node).pose.linear();
  for (const Eigen::Matrix3d& s : node.symmetries) {
    world::Pose pose = base;
    pose.linear() = base.linear() * s;
    EXPECT_TRUE(setCanonicalOrientation(pose, node).pose.linear().isApprox(expected, 1e-9));
  }
}

TEST(CanonicalOrientation, ALinkPutsItsLongAxisFirst) {
  const world::ObjectClass& link = objectClass("link");                 // axis priority x, z, y
  world::Pose pose = world::poseFromXyzRpy(0.5, 0, 0.0125, 0, 0, 2.5);  // long axis pointing backwards-left
  pose.linear() = pose.linear() * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Matrix3d r = setCanonicalOrientation(pose, link).pose.linear();
  EXPECT_GT(r.col(0).x(), 0.0);     // the long axis flipped towards the world's +x
  EXPECT_GT(r.col(2).z(), 0.9999);  // then z up (a 90 degree turn about the long axis)
  EXPECT_LT(symmetricRotationDistance(r, pose.linear(), link), 1e-6);
}

TEST(CanonicalOrientation, ThePreviousPoseAsReferenceAvoidsFlipsAt45Degrees) {
  const world::ObjectClass& node = objectClass("node");
  // A cube turning from 44 to 46 degrees: against the world frame its x jumps by 90 degrees...
  const world::Pose at44 = world::poseFromXyzRpy(0.5, 0, 0.025, 0, 0, 44 * M_PI / 180);
  const world::Pose at46 = world::poseFromXyzRpy(0.5, 0, 0.025, 0, 0, 46 * M_PI / 180);
  const world::Pose first = setCanonicalOrientation(at44, node).pose;
  const world::Pose world_ref = setCanonicalOrientation(at46, node).pose;
  EXPECT_NEAR(world::rotationAngle(first, world_ref), 88 * M_PI / 180, 1e-6);
  // ... against its previous pose it turns by 2 degrees.
  const world::Pose tracked = setCanonicalOrientation(at46, node, first.linear()).pose;
  EXPECT_NEAR(world::rotationAngle(first, tracked), 2 * M_PI / 180, 1e-6);
}

TEST(CanonicalOrientation, SymmetricDistanceIgnoresSymmetries) {
  const world::ObjectClass& link = objectClass("link");
  const Eigen::Matrix3d a = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d flipped = a * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(symmetricRotationDistance(a, flipped, link), 0.0, 1e-6);
  const Eigen::Matrix3d turned = a * Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(symmetricRotationDistance(a, turned, link), 0.1, 1e-6);
  // A quarter turn about z is not a symmetry of the link.
  const Eigen::Matrix3d quarter = a * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(symmetricRotationDistance(a, quarter, link), M_PI / 2, 1e-6);
}

// --- persistenceUpdate ---------------------------------------------------------------------------

TEST(Persistence, NewObjectsGetFreshNamesPerClass) {
  PersistenceFilter filter(classes());
  const auto& objects =
      filter.update({detection("node", 0.4, 0.0), detection("link", 0.5, 0.2), detection("node", 0.6, 0.1)});
  EXPECT_EQ(names(objects), (std::vector<std::string>{"node_1", "link_1", "node_2"}));
  for (const auto& object : objects) {
    EXPECT_EQ(object.missed, 0);
    EXPECT_EQ(object.seen, 1);
  }
}

TEST(Persistence, ObjectsThatStayOrMoveALittleKeepTheirNames) {
  PersistenceFilter filter(classes());
  filter.update({detection("node", 0.4, 0.0), detection("node", 0.6, 0.1), detection("link", 0.5, 0.2)});
  // Shuffled, moved by up to 2 cm.
  const auto& objects = filter.update(
      {detection("link", 0.51, 0.21), detection("node", 0.61, 0.11, 0.2), detection("node", 0.38, 0.005)});
  EXPECT_EQ(names(objects), (std::vector<std::string>{"link_1", "node_2", "node_1"}));
  EXPECT_EQ(objects[1].seen, 2);
}

TEST(Persistence, FarMovesClassChangesAndVanishedObjects) {
  PersistenceFilter filter(classes());
  filter.update({detection("node", 0.4, 0.0), detection("node", 0.6, 0.1)});
  // node_1 moved 5 cm (beyond d_max = 3 cm), node_2 is gone, a link where node_1 was.
  const auto& objects = filter.update({detection("node", 0.45, 0.0), detection("link", 0.4, 0.0)});
  EXPECT_EQ(names(objects), (std::vector<std::string>{"node_3", "link_1"}));
}

TEST(Persistence, OneMatchPerObjectClosestFirst) {
  PersistenceFilter filter(classes());
  filter.update({detection("node", 0.5, 0.0)});
  // Two detections near the one previous node: the closer keeps the name, in either order.
  for (const bool swapped : {false, true}) {
    PersistenceFilter f(classes());
    f.update({detection("node", 0.5, 0.0)});
    std::vector<Detection> next = {detection("node", 0.52, 0.0), detection("node", 0.505, 0.0)};
    if (swapped) {
      std::swap(next[0], next[1]);
    }
    const auto& objects = f.update(next);
    for (const auto& object : objects) {
      const bool closer = std::abs(object.pose.translation().x() - 0.505) < 1e-9;
      EXPECT_EQ(object.name, closer ? "node_1" : "node_2");
    }
  }
}

TEST(Persistence, UnseenObjectsAreKeptForKDetections) {
  PersistenceOptions options;
  options.keep_for = 2;
  PersistenceFilter filter(classes(), options);
  filter.update({detection("node", 0.4, 0.0), detection("node", 0.6, 0.1)});
  auto objects = filter.update({detection("node", 0.4, 0.0)});
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_EQ(objects[1].name, "node_2");
  EXPECT_EQ(objects[1].missed, 1);
  objects = filter.update({detection("node", 0.4, 0.0)});
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_EQ(objects[1].missed, 2);
  // Seen again within K: the name comes back.
  objects = filter.update({detection("node", 0.4, 0.0), detection("node", 0.6, 0.1)});
  EXPECT_EQ(names(objects), (std::vector<std::string>{"node_1", "node_2"}));
  filter.update({detection("node", 0.4, 0.0)});
  filter.update({detection("node", 0.4, 0.0)});
  objects = filter.update({detection("node", 0.4, 0.0)});
  EXPECT_EQ(names(objects), (std::vector<std::string>{"node_1"}));  // dropped after K misses
  // Names are never reused.
  objects = filter.update({detection("node", 0.4, 0.0), detection("node", 0.6, 0.1)});
  EXPECT_EQ(objects[1].name, "node_3");
}

TEST(Persistence, DetectionsAreSetToTheirCanonicalOrientationAgainstThePreviousPose) {
  PersistenceFilter filter(classes());
  filter.update({detection("node", 0.5, 0.0, 44 * M_PI / 180)});
  EXPECT_NEAR(world::rpyOf(filter.objects()[0].pose.linear()).z(), 44 * M_PI / 180, 1e-9);
  // Turned to 46 degrees and reported in another of its 24 frames: no jump.
  Detection turned = detection("node", 0.5, 0.0, 46 * M_PI / 180);
  turned.pose.linear() = turned.pose.linear() * objectClass("node").symmetries[5];
  filter.update({turned});
  EXPECT_NEAR(world::rpyOf(filter.objects()[0].pose.linear()).z(), 46 * M_PI / 180, 1e-9);
  // A new cube at 46 degrees: against the world frame, -44.
  filter.update({turned, detection("node", 0.7, 0.2, 46 * M_PI / 180)});
  EXPECT_NEAR(world::rpyOf(filter.objects()[1].pose.linear()).z(), -44 * M_PI / 180, 1e-9);
}

TEST(Persistence, ManyObjectsMatchLikeBruteForce) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(0.0, 10.0);
  std::normal_distribution<double> jitter(0.0, 0.005);
  std::vector<Detection> first;
  for (int i = 0; i < 2000; ++i) {
    first.push_back(detection(i % 3 == 0 ? "link" : "node", coordinate(random), coordinate(random)));
  }
  PersistenceFilter filter(classes());
  const std::vector<TrackedObject> before = filter.update(first);
  std::vector<Detection> moved = first;
  for (auto& d : moved) {
    d.pose.translation() += Eigen::Vector3d(jitter(random), jitter(random), 0);
  }
  std::shuffle(moved.begin(), moved.end(), random);
  const auto& after = filter.update(moved);
  // Brute force: every moved detection's name is the one of the nearest original of its class.
  int agree = 0;
  for (const auto& object : after) {
    double best = 1e9;
    std::string name;
    for (const auto& old : before) {
      const double d = (old.pose.translation() - object.pose.translation()).norm();
      if (old.object_class == object.object_class && d < best) {
        best = d;
        name = old.name;
      }
    }
    agree += name == object.name;
  }
  EXPECT_GE(agree, 1990);  // points a few mm apart may pair the other way round
}

TEST(Persistence, CrowdedObjectsMatchClosestPairFirstLikeAGreedyReference) {
  // Clusters of objects closer than d_max to each other, moved by up to 2 cm: each detection has
  // several candidates, so the order in which pairs are taken matters. Reference: Algorithm 1's
  // rule spelled out by brute force, all same-class pairs within d_max sorted by distance, a
  // pair taken when neither side is matched yet.
  // 600 objects, and 2,800 (from 2,048 the update runs on two threads).
  for (const int clusters : {150, 700}) {
    SCOPED_TRACE(std::to_string(clusters * 4) + " objects");
    std::mt19937 random(7);
    const double side = std::sqrt(clusters / 150.0) * 3.0;  // the same density
    std::uniform_real_distribution<double> centre(0.0, side);
    std::uniform_real_distribution<double> spread(-0.02, 0.02);
    std::vector<Detection> first;
    for (int cluster = 0; cluster < clusters; ++cluster) {
      const double cx = centre(random);
      const double cy = centre(random);
      for (int i = 0; i < 4; ++i) {
        first.push_back(detection(i % 2 == 0 ? "node" : "link", cx + spread(random), cy + spread(random)));
      }
    }
    PersistenceFilter filter(classes());
    const std::vector<TrackedObject> before = filter.update(first);
    std::vector<Detection> moved = first;
    for (auto& d : moved) {
      d.pose.translation() += Eigen::Vector3d(spread(random) / 2, spread(random) / 2, 0);
    }
    std::shuffle(moved.begin(), moved.end(), random);
    const auto& after = filter.update(moved);
    ASSERT_EQ(after.size(), moved.size());

    const double d_max = filter.options().max_distance;
    std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
    for (std::size_t d = 0; d < moved.size(); ++d) {
      for (std::size_t p = 0; p < before.size(); ++p) {
        const double distance = (moved[d].pose.translation() - before[p].pose.translation()).norm();
        if (before[p].object_class == moved[d].object_class && distance <= d_max) {
          pairs.emplace_back(distance, d, p);
        }
      }
    }
    std::sort(pairs.begin(), pairs.end());
    std::vector<std::string> expected(moved.size());
    std::vector<bool> taken(before.size(), false);
    for (const auto& [distance, d, p] : pairs) {
      if (expected[d].empty() && !taken[p]) {
        expected[d] = before[p].name;
        taken[p] = true;
      }
    }
    int matched = 0;
    int contested = 0;
    for (std::size_t d = 0; d < moved.size(); ++d) {
      if (!expected[d].empty()) {
        EXPECT_EQ(after[d].name, expected[d]) << "detection " << d;
        ++matched;
      } else {
        EXPECT_EQ(after[d].seen, 1) << "detection " << d << " should be new";
      }
    }
    for (std::size_t d = 0; d < moved.size(); ++d) {
      int candidates = 0;
      for (const auto& [distance, pd, p] : pairs) {
        candidates += pd == d ? 1 : 0;
      }
      contested += candidates > 1 ? 1 : 0;
    }
    EXPECT_GT(matched, clusters * 10 / 3);   // most keep a name ...
    EXPECT_GT(contested, clusters * 2 / 3);  // ... and many had a choice to make
  }
}

}  // namespace
}  // namespace costar::perception
