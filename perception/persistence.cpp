#include "perception/persistence.h"

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/box.hpp>
#include <boost/geometry/geometries/point.hpp>
#include <boost/geometry/index/rtree.hpp>

#include <algorithm>
#include <map>
#include <optional>
#include <span>
#include <tuple>

#include "perception/canonical_orientation.h"

namespace costar::perception {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;

namespace {

using Point = bg::model::point<double, 3, bg::cs::cartesian>;
using Entry = std::pair<Point, std::size_t>;  // position, index into the previous objects
using Box = bg::model::box<Point>;
using Tree = bgi::rtree<Entry, bgi::rstar<16>>;

Point toPoint(const Eigen::Vector3d& p) { return Point(p.x(), p.y(), p.z()); }

/// How many detections ahead a matched previous object is fetched into the cache.
constexpr std::size_t kPrefetchAhead = 8;

}  // namespace

/// One R*-tree per class (the "same type" test of Algorithm 1 is the choice of tree).
struct PersistenceFilter::Index {
  std::map<std::string, Tree, std::less<>> trees;
  std::vector<Entry> hits;  // a query's results, reused
};

PersistenceFilter::PersistenceFilter(std::vector<world::ObjectClass> classes, PersistenceOptions options)
    : classes_(std::move(classes)), options_(options), index_(std::make_unique<Index>()) {}

PersistenceFilter::~PersistenceFilter() = default;
PersistenceFilter::PersistenceFilter(PersistenceFilter&&) noexcept = default;
PersistenceFilter& PersistenceFilter::operator=(PersistenceFilter&&) noexcept = default;

void PersistenceFilter::clear() {
  objects_.clear();
  index_->trees.clear();
}

const std::vector<TrackedObject>& PersistenceFilter::update(const std::vector<Detection>& detections) {
  const std::vector<TrackedObject> previous = std::move(objects_);
  objects_.clear();
  objects_.reserve(detections.size() + previous.size());
  const double max_distance = options_.max_distance;
  const double max_squared = max_distance * max_distance;

  // Every (detection, previous object of its class) pair within d_max, from one box query per
  // detection in its class's tree.
  struct Pair {
    double squared;
    std::uint32_t detection;
    std::uint32_t previous;
    bool operator<(const Pair& other) const {
      return std::tie(squared, detection, previous) < std::tie(other.squared, other.detection, other.previous);
    }
  };
  std::vector<Pair> pairs;
  pairs.reserve(detections.size());
  std::vector<Entry>& hits = index_->hits;
  const Tree* tree = nullptr;
  const std::string* tree_class = nullptr;
  for (std::size_t d = 0; d < detections.size(); ++d) {
    const std::string& object_class = detections[d].object_class;
    if (tree_class == nullptr || *tree_class != object_class) {
      const auto found = index_->trees.find(object_class);
      tree = found == index_->trees.end() ? nullptr : &found->second;
      tree_class = &object_class;
    }
    if (tree == nullptr || tree->empty()) {
      continue;
    }
    const Point p = toPoint(detections[d].pose.translation());
    const Box around(Point(p.get<0>() - max_distance, p.get<1>() - max_distance, p.get<2>() - max_distance),
                     Point(p.get<0>() + max_distance, p.get<1>() + max_distance, p.get<2>() + max_distance));
    hits.clear();
    tree->query(bgi::intersects(around), std::back_inserter(hits));
    for (const Entry& hit : hits) {
      const double squared = bg::comparable_distance(p, hit.first);
      if (squared <= max_squared) {
        pairs.push_back({squared, static_cast<std::uint32_t>(d), static_cast<std::uint32_t>(hit.second)});
      }
    }
  }
  // Closest pairs first: a pair counts when neither side is matched yet. A pair whose detection
  // and previous object are in no other pair is taken whatever the order, so only the
  // contested pairs need sorting.
  std::vector<std::uint8_t> detection_pairs(detections.size(), 0);
  std::vector<std::uint8_t> previous_pairs(previous.size(), 0);
  for (const Pair& pair : pairs) {
    detection_pairs[pair.detection] = std::min(detection_pairs[pair.detection] + 1, 2);
    previous_pairs[pair.previous] = std::min(previous_pairs[pair.previous] + 1, 2);
  }
  std::vector<std::optional<std::size_t>> match(detections.size());
  std::vector<bool> taken(previous.size(), false);
  const auto contested = std::partition(pairs.begin(), pairs.end(), [&](const Pair& pair) {
    return detection_pairs[pair.detection] == 1 && previous_pairs[pair.previous] == 1;
  });
  for (auto pair = pairs.begin(); pair != contested; ++pair) {
    match[pair->detection] = pair->previous;
    taken[pair->previous] = true;
  }
  std::sort(contested, pairs.end());
  for (const Pair& pair : std::span(contested, pairs.end())) {
    if (!match[pair.detection] && !taken[pair.previous]) {
      match[pair.detection] = pair.previous;
      taken[pair.previous] = true;
    }
  }

  const auto find_class = [this](const std::string& name) -> const world::ObjectClass* {
    for (const auto& object_class : classes_) {
      if (object_class.name == name) {
        return &object_class;
      }
    }
    return nullptr;
  };
  for (std::size_t d = 0; d < detections.size(); ++d) {
    // The matched previous objects are read in the detections' order, scattered over memory:
    // ask for the one a few detections ahead now, so it is in the cache when it is read.
    if (const std::size_t ahead = d + kPrefetchAhead; ahead < detections.size() && match[ahead]) {
      const auto* bytes = reinterpret_cast<const char*>(&previous[*match[ahead]]);
      for (std::size_t offset = 0; offset < sizeof(TrackedObject); offset += 64) {
        __builtin_prefetch(bytes + offset);
      }
    }
    const Detection& detection = detections[d];
    TrackedObject object;
    object.object_class = detection.object_class;
    object.confidence = detection.confidence;
    object.pose = detection.pose;
    object.color = detection.color;
    Eigen::Matrix3d reference = options_.new_object_reference;
    if (match[d]) {
      const TrackedObject& before = previous[*match[d]];
      object.name = before.name;
      object.seen = before.seen + 1;
      if (!object.color) {
        object.color = before.color;
      }
      reference = before.pose.linear();
    } else {
      auto counter = std::find_if(counters_.begin(), counters_.end(),
                                  [&](const auto& entry) { return entry.first == detection.object_class; });
      if (counter == counters_.end()) {
        counters_.emplace_back(detection.object_class, 0);
        counter = counters_.end() - 1;
      }
      object.name = detection.object_class + "_" + std::to_string(++counter->second);
      object.seen = 1;
    }
    if (options_.canonical_orientation) {
      if (const world::ObjectClass* object_class = find_class(detection.object_class)) {
        object.pose = setCanonicalOrientation(object.pose, *object_class, reference).pose;
      }
    }
    objects_.push_back(std::move(object));
  }
  // Previous objects nobody matched: kept for a while, or dropped.
  for (std::size_t p = 0; p < previous.size(); ++p) {
    if (!taken[p] && previous[p].missed < options_.keep_for) {
      TrackedObject kept = previous[p];
      ++kept.missed;
      objects_.push_back(std::move(kept));
    }
  }
  // The next update's trees, bulk-loaded (packing) per class.
  std::map<std::string, std::vector<Entry>, std::less<>> entries;
  std::vector<Entry>* current = nullptr;
  const std::string* current_class = nullptr;
  for (std::size_t i = 0; i < objects_.size(); ++i) {
    const std::string& object_class = objects_[i].object_class;
    if (current_class == nullptr || *current_class != object_class) {
      current = &entries[object_class];
      current_class = &object_class;
    }
    current->emplace_back(toPoint(objects_[i].pose.translation()), i);
  }
  index_->trees.clear();
  for (auto& [name, values] : entries) {
    index_->trees.emplace(name, Tree(values.begin(), values.end()));
  }
  return objects_;
}

}  // namespace costar::perception
