#include "sim/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

#include "core/paths.h"

namespace costar::sim {
namespace {

std::vector<world::ObjectClass> classes() { return world::loadObjectClasses(dataRoot() / "data/objects"); }

TEST(Scene, FixedAndRandomPartsAreOnTheTableInTheirRegionsAndApart) {
  const Scene scene = parseScene(R"({"seed": 3, "parts": [
      {"class": "node", "color": "red", "at": [0.5, -0.2, 90]},
      {"class": "node", "count": 4, "region": "right"},
      {"class": "link", "count": 2, "region": "left"}]})",
                                 "test");
  const auto parts = placeParts(scene, classes());
  ASSERT_EQ(parts.size(), 7u);
  EXPECT_EQ(parts[0].name, "node_0");
  EXPECT_EQ(parts[0].color, "red");
  EXPECT_TRUE(parts[0].pose.translation().head<2>().isApprox(Eigen::Vector2d(0.5, -0.2)));
  EXPECT_NEAR(parts[0].pose.translation().z(), 0.0255, 1e-9);
  EXPECT_TRUE((parts[0].pose.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-9));
  EXPECT_EQ(parts[6].name, "link_1");
  const auto regions = defaultRegions();
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const Region& region = regions.at(parts[i].object_class == "node" ? "right" : "left");
    const Eigen::Vector2d xy = parts[i].pose.translation().head<2>();
    EXPECT_TRUE((xy.array() >= region.min.array()).all() && (xy.array() <= region.max.array()).all()) << parts[i].name;
    for (std::size_t j = 0; j < i; ++j) {
      EXPECT_GT((parts[j].pose.translation() - parts[i].pose.translation()).head<2>().norm(), 0.05);
    }
  }
}

TEST(Scene, PlacementIsDeterministicForASeedAndVariesWithIt) {
  const Scene scene = parseScene(R"({"seed": 11, "parts": [{"class": "node", "count": 3}]})", "test");
  const auto a = placeParts(scene, classes());
  const auto b = placeParts(scene, classes());
  const auto c = placeParts(scene, classes(), 12);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(a[i].pose.isApprox(b[i].pose));
  }
  EXPECT_FALSE(a[0].pose.isApprox(c[0].pose));
}

std::string problem(const std::string& json) {
  try {
    placeParts(parseScene(json, "bad.json"), classes());
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no error";
}

/// Corners of a part's footprint (its class's bounding rectangle turned by its yaw).
std::vector<Eigen::Vector2d> corners(const PartPlacement& part, const world::ObjectClass& object) {
  const Eigen::AlignedBox3d bounds = object.bounds();
  std::vector<Eigen::Vector2d> points;
  for (const auto& corner :
       {Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, -1), Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1)}) {
    const Eigen::Vector3d local(bounds.center().x() + 0.5 * corner.x() * bounds.sizes().x(),
                                bounds.center().y() + 0.5 * corner.y() * bounds.sizes().y(), 0.0);
    points.push_back((part.pose * local).head<2>());
  }
  return points;
}

double pointToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return (a + t * (b - a) - p).norm();
}

/// Distance between two disjoint convex polygons: the nearest vertex-to-edge pair.
double polygonDistance(const std::vector<Eigen::Vector2d>& p, const std::vector<Eigen::Vector2d>& q) {
  double nearest = std::numeric_limits<double>::infinity();
  for (int pass = 0; pass < 2; ++pass) {
    const auto& points = pass == 0 ? p : q;
    const auto& edges = pass == 0 ? q : p;
    for (const auto& point : points) {
      for (std::size_t i = 0; i < edges.size(); ++i) {
        nearest = std::min(nearest, pointToSegment(point, edges[i], edges[(i + 1) % edges.size()]));
      }
    }
  }
  return nearest;
}

TEST(Scene, CrowdedPartsKeepTheGapBetweenTheirFootprintsNotTheirBoundingCircles) {
  // 8 nodes and 3 links in the right half with 5 mm gaps: too many for bounding circles
  // (a link's circle is 15 cm across), room enough for the parts' turned rectangles.
  const Scene scene = parseScene(R"({"seed": 5, "min_gap": 0.005, "parts": [
      {"class": "link", "count": 3, "region": "right"}, {"class": "node", "count": 8, "region": "right"}]})",
                                 "test");
  const auto all = classes();
  const auto find = [&](const std::string& name) {
    return *std::find_if(all.begin(), all.end(), [&](const world::ObjectClass& c) { return c.name == name; });
  };
  const auto parts = placeParts(scene, all);
  ASSERT_EQ(parts.size(), 11u);
  double closest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < parts.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      const double gap = polygonDistance(corners(parts[i], find(parts[i].object_class)),
                                         corners(parts[j], find(parts[j].object_class)));
      EXPECT_GE(gap, 0.005 - 1e-9) << parts[i].name << " and " << parts[j].name;
      closest = std::min(closest, gap);
    }
  }
  // Crowded indeed: some pair is closer than a finger is thick.
  EXPECT_LT(closest, 0.02);
}

TEST(Scene, FootprintsCloserThanAGapAreFoundWhateverTheirTurn) {
  const auto all = classes();
  const world::ObjectClass& link =
      *std::find_if(all.begin(), all.end(), [](const auto& c) { return c.name == "link"; });
  // Two links side by side along y, 25 mm wide: 5 mm apart at 30 mm between centres.
  const Footprint a = Footprint::of(link, 0.5, 0.0, 0.0);
  EXPECT_TRUE(closerThan(a, Footprint::of(link, 0.5, 0.030, 0.0), 0.006));
  EXPECT_FALSE(closerThan(a, Footprint::of(link, 0.5, 0.030, 0.0), 0.004));
  // Touching (0 mm apart) counts as overlapping only with a gap above 0; a negative gap allows that much overlap.
  EXPECT_FALSE(closerThan(a, Footprint::of(link, 0.5, 0.0245, 0.0), -0.001));
  EXPECT_TRUE(closerThan(a, Footprint::of(link, 0.5, 0.0245, 0.0), 0.0));
  // Crossed at right angles: the other reaches 75 mm from its centre, this one 12.5 mm.
  EXPECT_TRUE(closerThan(a, Footprint::of(link, 0.5, 0.085, M_PI / 2), 0.0));
  EXPECT_FALSE(closerThan(a, Footprint::of(link, 0.5, 0.089, M_PI / 2), 0.001));  // 1.5 mm apart
  EXPECT_TRUE(closerThan(a, Footprint::of(link, 0.5, 0.089, M_PI / 2), 0.002));
  // A node turned 45 degrees, a corner 2 mm from the link's end: grown by 1.5 mm, the corner
  // reaches 2.1 mm further along its diagonal.
  const world::ObjectClass& node =
      *std::find_if(all.begin(), all.end(), [](const auto& c) { return c.name == "node"; });
  const Footprint turned = Footprint::of(node, 0.5 + 0.075 + 0.025 * std::sqrt(2.0) + 0.002, 0.0, M_PI / 4);
  EXPECT_FALSE(closerThan(a, turned, 0.001));
  EXPECT_TRUE(closerThan(a, turned, 0.003));
}

/// Placements of a cluttered scene (every part fixed with "at").
std::vector<PartPlacement> placed(const ClutteredScene& cluttered) { return placeParts(cluttered.scene, classes()); }

TEST(Scene, ClutteredScenesAreDeterministicOnTheTableAndApartOrTouching) {
  const auto all = classes();
  const auto find = [&](const std::string& name) {
    return *std::find_if(all.begin(), all.end(), [&](const world::ObjectClass& c) { return c.name == name; });
  };
  const std::vector<std::pair<std::string, int>> counts = {{"node", 5}, {"link", 3}};
  const auto nearest = [&](const std::vector<PartPlacement>& parts, std::size_t i) {
    double closest = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < parts.size(); ++j) {
      if (j != i) {
        closest = std::min(closest, polygonDistance(corners(parts[i], find(parts[i].object_class)),
                                                    corners(parts[j], find(parts[j].object_class))));
      }
    }
    return closest;
  };
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    // Apart: every part 1 cm or more from every other, on the table, as many as asked.
    std::mt19937_64 random(seed);
    const ClutteredScene apart = clutteredScene(all, counts, 0.0, random, "apart");
    EXPECT_EQ(apart.touching_parts, 0);
    const auto parts = placed(apart);
    ASSERT_EQ(parts.size(), 8u);
    const Region table = defaultRegions().at("table");
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const Eigen::Vector2d xy = parts[i].pose.translation().head<2>();
      EXPECT_TRUE((xy.array() >= table.min.array()).all() && (xy.array() <= table.max.array()).all());
      EXPECT_GE(nearest(parts, i), 0.01 - 1e-9) << "seed " << seed << ", " << parts[i].name;
    }
    // The same seed, the same scene; the stream goes on from where the scene left it.
    std::mt19937_64 again(seed);
    const auto same = placed(clutteredScene(all, counts, 0.0, again, "apart"));
    for (std::size_t i = 0; i < parts.size(); ++i) {
      EXPECT_TRUE(parts[i].pose.isApprox(same[i].pose, 0.0)) << parts[i].name;
    }
    EXPECT_EQ(random(), again());

    // Touching: most parts against a side of another, 1 mm from it along that side's normal
    // (a part turned up to 12 degrees off its neighbour, or slid past the end of a shorter
    // side, is a few mm from it elsewhere), so nearer to it than the 1 cm between the others.
    std::mt19937_64 touching_random(seed);
    const ClutteredScene touching = clutteredScene(all, counts, 1.0, touching_random, "touching");
    EXPECT_GE(touching.touching_parts, 4) << "seed " << seed;
    const auto touching_parts = placed(touching);
    int near = 0;
    for (std::size_t i = 0; i < touching_parts.size(); ++i) {
      near += nearest(touching_parts, i) < 0.009 ? 1 : 0;
    }
    EXPECT_GE(near, touching.touching_parts) << "seed " << seed;
    // Differs from the scene with parts apart.
    EXPECT_FALSE(touching_parts[0].pose.isApprox(parts[0].pose, 1e-6) &&
                 touching_parts[1].pose.isApprox(parts[1].pose, 1e-6));
  }
  std::mt19937_64 random(1);
  EXPECT_THROW(clutteredScene(all, {{"widget", 1}}, 0.0, random, "bad"), std::runtime_error);
}

TEST(Scene, ProblemsAreNamed) {
  EXPECT_EQ(problem(R"({"parts": [{"class": "gear"}]})"),
            "scene 'bad.json': parts[0].class: unknown object class 'gear' (known: link, node)");
  EXPECT_EQ(problem(R"({"parts": [{"class": "node"}, {"class": "node", "region": "moon"}]})"),
            "scene 'bad.json': parts[1].region: unknown region 'moon' (known: left, right, table)");
  EXPECT_NE(problem(R"({"parts": [{"class": "node", "count": 60, "region": "right"}]})").find("parts[0]: cannot fit"),
            std::string::npos);
  EXPECT_NE(problem(R"({"parts": [{"class": "node", "color": "purple"}]})").find("parts[0].color: "),
            std::string::npos);
  EXPECT_EQ(problem(R"({"parts": 3})"), "scene 'bad.json': parts: must be a list [...], not 3");
  EXPECT_THROW(loadScene("/nonexistent.json"), std::runtime_error);
}

// Issue 10, bug 2: the regions loop iterated items() of a temporary (freed memory; valgrind and
// AddressSanitizer report it) and failed with "cannot use at() with null".
TEST(Scene, ASceneWrittenAsAFileReadsBackTheSame) {
  // A cluttered scene (every part fixed) and one with regions, counts and a camera offset.
  std::mt19937_64 random(5);
  const Scene cluttered = clutteredScene(classes(), {{"node", 4}, {"link", 2}}, 0.4, random, "cluttered").scene;
  const Scene mixed = parseScene(R"({"description": "mixed", "seed": 9, "min_gap": 0.01,
      "regions": {"corner": {"x": [0.55, 0.7], "y": [0.2, 0.35]}},
      "camera_offset": {"distance": 0.05, "angle_deg": 5, "seed": 7},
      "parts": [{"class": "node", "color": "red", "at": [0.5, -0.2, 30]},
                {"class": "link", "at": [0.5, -0.2, 120], "height": 0.05},
                {"class": "node", "count": 2, "region": "corner"}, {"class": "link"}]})",
                                 "mixed.json");
  for (const Scene& scene : {cluttered, mixed}) {
    const std::string text = sceneFileText(scene);
    const Scene back = parseScene(text, "back.json");
    EXPECT_EQ(back.description, scene.description);
    EXPECT_EQ(back.seed, scene.seed);
    EXPECT_EQ(back.min_gap, scene.min_gap);
    EXPECT_EQ(back.regions.size(), scene.regions.size());
    EXPECT_EQ(back.camera_offset.has_value(), scene.camera_offset.has_value());
    ASSERT_EQ(back.parts.size(), scene.parts.size());
    for (std::size_t i = 0; i < scene.parts.size(); ++i) {
      EXPECT_EQ(back.parts[i].object_class, scene.parts[i].object_class);
      EXPECT_EQ(back.parts[i].color, scene.parts[i].color);
      EXPECT_EQ(back.parts[i].count, scene.parts[i].count);
      EXPECT_EQ(back.parts[i].region, scene.parts[i].region);
      EXPECT_EQ(back.parts[i].at, scene.parts[i].at);  // exactly: doubles written in full
      EXPECT_EQ(back.parts[i].height, scene.parts[i].height);
    }
    // The same placements from both.
    const auto placed_parts = placeParts(scene, classes());
    const auto placed_back = placeParts(back, classes());
    ASSERT_EQ(placed_back.size(), placed_parts.size());
    for (std::size_t i = 0; i < placed_parts.size(); ++i) {
      EXPECT_TRUE(placed_back[i].pose.isApprox(placed_parts[i].pose, 0.0)) << placed_parts[i].name;
    }
    EXPECT_EQ(sceneFileText(back), text);
  }
  EXPECT_EQ(parseScene(sceneFileText(mixed), "m").camera_offset->distance, 0.05);
  // A part with a height starts that far up: the link over the node, the node on the table.
  const auto stacked = placeParts(mixed, classes());
  EXPECT_NEAR(stacked[1].pose.translation().z() - stacked[0].pose.translation().z(), 0.05 - 0.025 + 0.0125, 1e-12);
  EXPECT_EQ(parseScene(sceneFileText(mixed), "m").regions.at("corner").max, Eigen::Vector2d(0.7, 0.35));
}

TEST(Scene, CustomRegionsAreReadAndUsed) {
  const Scene scene = parseScene(R"({"seed": 4,
      "regions": {"corner": {"x": [0.55, 0.7], "y": [0.2, 0.35]}, "strip": {"x": [0.3, 0.35], "y": [-0.3, 0.3]}},
      "parts": [{"class": "node", "count": 2, "region": "corner"}, {"class": "link", "region": "strip"}]})",
                                 "regions.json");
  ASSERT_EQ(scene.regions.size(), 5u);  // table, left, right and the two custom ones
  EXPECT_EQ(scene.regions.at("corner").min, Eigen::Vector2d(0.55, 0.2));
  EXPECT_EQ(scene.regions.at("corner").max, Eigen::Vector2d(0.7, 0.35));
  EXPECT_EQ(scene.regions.at("strip").min, Eigen::Vector2d(0.3, -0.3));
  const auto parts = placeParts(scene, classes());
  ASSERT_EQ(parts.size(), 3u);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Region& region = scene.regions.at(i < 2 ? "corner" : "strip");
    const Eigen::Vector2d xy = parts[i].pose.translation().head<2>();
    EXPECT_TRUE((xy.array() >= region.min.array()).all() && (xy.array() <= region.max.array()).all())
        << parts[i].name << " at " << xy.transpose();
  }
}

// Issue 10, bug 6: values that were silently accepted (or truncated) are errors naming the field.
TEST(Scene, BadValuesAreErrorsNamingTheField) {
  const std::string prefix = "scene 'bad.json': ";
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "count": 4294967297}]})"),
            prefix + "parts[0].count: must be a whole number from 1 to 100, not 4294967297");
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "count": 2.5}]})"),
            prefix + "parts[0].count: must be a whole number from 1 to 100, not 2.5");
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "count": -1}]})"),
            prefix + "parts[0].count: must be a whole number from 1 to 100, not -1");
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "count": "3"}]})"),
            prefix + "parts[0].count: must be a whole number from 1 to 100, not \"3\"");
  EXPECT_EQ(problem(R"({"min_gap": -0.01, "parts": []})"), prefix + "min_gap: must be from 0 to 0.5 (m), not -0.01");
  EXPECT_EQ(problem(R"({"min_gap": "wide", "parts": []})"), prefix + "min_gap: must be a finite number, not \"wide\"");
  EXPECT_EQ(problem(R"({"seed": -3, "parts": []})").substr(0, prefix.size() + 6), prefix + "seed: ");
  EXPECT_EQ(problem(R"({"parts": [{"class": 7}]})"), prefix + "parts[0].class: must be a string, not 7");
  EXPECT_EQ(problem(R"({"parts": [{"colour": "red", "class": "node"}]})"),
            prefix + "parts[0].colour: unknown field (known: class, color, count, at, height, region)");
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "at": [0.5, 0], "height": -0.1}]})"),
            prefix + "parts[0].height: must be within 0 .. 0.5 m above the table, got -0.1");
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "region": "left", "height": 0.05}]})"),
            prefix + "parts[0].height: only a part placed with \"at\" has a height");
  EXPECT_EQ(problem(R"({"regoins": {}, "parts": []})"),
            prefix +
                "regoins: unknown field (known: description, seed, min_gap, camera_offset, regions, parts, jig, wire, "
                "workpiece, power_tool, person)");
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "at": [0.5]}]})"),
            prefix + "parts[0].at: must be [x, y] or [x, y, yaw] (m, m, degrees), not [0.5]");
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "at": [0.5, null]}]})"),
            prefix + "parts[0].at[1]: must be a finite number, not null");
  EXPECT_NE(problem(R"({"parts": [{"class": "node", "at": [9, 0]}]})").find("parts[0].at: lies off the table top"),
            std::string::npos);
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "at": [0.5, 0], "region": "left"}]})"),
            prefix + "parts[0]: has both \"at\" (a fixed place) and \"region\" (a random place); give one");
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "at": [0.5, 0], "count": 2}]})"),
            prefix + "parts[0].count: a part placed with \"at\" must have count 1");
  EXPECT_EQ(problem(R"({"parts": [{}]})"), prefix + "parts[0].class: missing (the object class, e.g. \"node\")");
  EXPECT_EQ(problem(R"({"regions": {"a": {"x": [0.6, 0.4], "y": [0, 0.1]}}, "parts": []})"),
            prefix + "regions.a.x: must be [low, high] with low < high, not [0.6,0.4]");
  EXPECT_EQ(problem(R"({"regions": {"a": {"x": [0.4, 0.6]}}, "parts": []})").substr(0, prefix.size() + 21),
            prefix + "regions.a.y: missing ");
  EXPECT_NE(problem(R"({"regions": {"a": {"x": [0.4, 3], "y": [0, 0.1]}}, "parts": []})")
                .find("regions.a: lies off the table top"),
            std::string::npos);
  EXPECT_EQ(problem(R"({"regions": [], "parts": []})"), prefix + "regions: must be an object {...}, not []");
  EXPECT_EQ(problem(R"({"parts": []})"), "no error");
}

// Issue 14: the camera moved from its drawn mounting, a scene option validated like the others.
TEST(Scene, CameraOffsetIsReadAndItsProblemsAreNamed) {
  const std::string prefix = "scene 'bad.json': ";
  EXPECT_EQ(problem(R"({"camera_offset": {"xyz": [0.03, 0, -0.04], "rpy_deg": [0, 3, 4]}, "parts": []})"), "no error");
  EXPECT_EQ(problem(R"({"camera_offset": {"distance": 0.05, "angle_deg": 5, "seed": 7}, "parts": []})"), "no error");
  EXPECT_EQ(problem(R"({"camera_offset": [0.05], "parts": []})"),
            prefix + "camera_offset: must be an object {...}, not [0.05]");
  EXPECT_EQ(problem(R"({"camera_offset": {"distanse": 0.05}, "parts": []})"),
            prefix + "camera_offset.distanse: unknown field (known: xyz, rpy_deg, distance, angle_deg, seed)");
  EXPECT_EQ(problem(R"({"camera_offset": {}, "parts": []})"),
            prefix +
                "camera_offset: needs either \"xyz\"/\"rpy_deg\" (a fixed offset) or \"distance\"/\"angle_deg\" "
                "(a random direction), not neither");
  EXPECT_EQ(
      problem(R"({"camera_offset": {"xyz": [0, 0, 0], "distance": 0.1}, "parts": []})").substr(0, prefix.size() + 28),
      prefix + "camera_offset: needs either ");
  EXPECT_EQ(problem(R"({"camera_offset": {"xyz": [0, 0]}, "parts": []})"),
            prefix + "camera_offset.xyz: must be [x, y, z] in m, not [0,0]");
  EXPECT_EQ(problem(R"({"camera_offset": {"xyz": [0, "a", 0]}, "parts": []})"),
            prefix + "camera_offset.xyz[1]: must be a finite number, not \"a\"");
  EXPECT_EQ(problem(R"({"camera_offset": {"xyz": [0.6, 0, 0]}, "parts": []})"),
            prefix + "camera_offset.xyz: the camera may move at most 0.5 m, not [0.6,0,0]");
  EXPECT_EQ(problem(R"({"camera_offset": {"rpy_deg": [0, 90, 0]}, "parts": []})"),
            prefix + "camera_offset.rpy_deg: the camera may turn at most 45 degrees about each axis, not [0,90,0]");
  EXPECT_EQ(problem(R"({"camera_offset": {"distance": -0.1}, "parts": []})"),
            prefix + "camera_offset.distance: must be from 0 to 0.5 (m), not -0.1");
  EXPECT_EQ(problem(R"({"camera_offset": {"angle_deg": 50}, "parts": []})"),
            prefix + "camera_offset.angle_deg: must be from 0 to 45 (degrees), not 50");
  EXPECT_EQ(problem(R"({"camera_offset": {"distance": 0.1, "seed": 1.5}, "parts": []})").substr(0, prefix.size() + 20),
            prefix + "camera_offset.seed: ");
}

TEST(Scene, UnreadableFilesAreNamedAsSuch) {
  const auto message = [](const std::filesystem::path& file) {
    try {
      loadScene(file);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("/nonexistent/scene.json"),
            "cannot read scene file '/nonexistent/scene.json': No such file or directory");
  const std::filesystem::path folder = std::filesystem::temp_directory_path();
  EXPECT_EQ(message(folder), "cannot read scene file '" + folder.string() + "': it is a folder");
  // Issue 27: --scene /dev/zero read forever (400 MB in 6 s).
  EXPECT_EQ(message("/dev/zero"), "cannot read scene file '/dev/zero': not a regular file (a device, pipe or socket)");
}

// Issue 27: two parts placed with "at" on the same spot started inside each other, and the
// physics threw them apart at the first step.
TEST(Scene, PartsPlacedInsideEachOtherAreRefusedNamingBoth) {
  const auto problem = [](const std::string& text) {
    try {
      placeParts(parseScene(text, "s.json"), classes());
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("placed");
  };
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "at": [0.5, 0.1, 0]}, {"class": "link", "at": [0.3, -0.2, 0]},
                                 {"class": "node", "at": [0.51, 0.1, 45]}]})"),
            "scene 's.json': parts[0] (node at 0.5, 0.1) and parts[2] (node at 0.51, 0.1) overlap: the simulation "
            "would throw them apart (move one, or give it a \"height\" to lie on the other)");
  // Apart, touching, or one lying on the other: placed.
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "at": [0.5, 0.1, 0]}, {"class": "node", "at": [0.6, 0.1, 0]}]})"),
            "placed");
  EXPECT_EQ(problem(R"({"parts": [{"class": "node", "at": [0.5, -0.2, 30]},
                                 {"class": "link", "at": [0.5, -0.2, 120], "height": 0.05}]})"),
            "placed");
  // Random placements keep clear of a fixed part that comes after them in the list.
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    const Scene scene = parseScene(R"({"parts": [{"class": "node", "count": 4, "region": "corner"},
                                                {"class": "node", "at": [0.575, 0.225, 0]}],
                                      "regions": {"corner": {"x": [0.45, 0.7], "y": [0.1, 0.35]}}})",
                                   "s.json");
    const auto parts = placeParts(scene, classes(), seed);
    const auto& fixed = parts.back().pose.translation();
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      // 5 cm cubes: closer than 5 cm, they would be inside each other.
      EXPECT_GT((parts[i].pose.translation() - fixed).head<2>().norm(), 0.05) << "seed " << seed << ", part " << i;
    }
  }
}

// Issue 27: a key given twice was taken silently (the last one).
TEST(Scene, AKeyGivenTwiceIsRefused) {
  try {
    parseScene(R"({"parts": [{"class": "node", "class": "link", "region": "left"}]})", "s.json");
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "scene 's.json': parts[0]: key 'class' appears twice (a key may appear once in an object)");
  }
}

TEST(Scene, TheSceneFilesInTheRepositoryLoad) {
  for (const char* name : {"one_node", "assembly", "clutter"}) {
    const Scene scene = loadScene(dataRoot() / "sim/scenes" / (std::string(name) + ".json"));
    EXPECT_FALSE(placeParts(scene, classes()).empty()) << name;
  }
}

}  // namespace
}  // namespace costar::sim
