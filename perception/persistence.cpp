#include "perception/persistence.h"

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point.hpp>
#include <boost/geometry/index/rtree.hpp>

#include <algorithm>
#include <map>
#include <queue>
#include <tuple>

#include "perception/canonical_orientation.h"

namespace costar::perception {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;

namespace {

using Point = bg::model::point<double, 3, bg::cs::cartesian>;
using Entry = std::pair<Point, std::size_t>;  // position, index into the previous objects
using Tree = bgi::rtree<Entry, bgi::rstar<16>>;

Point toPoint(const Eigen::Vector3d& p) { return Point(p.x(), p.y(), p.z()); }

}  // namespace

/// One R*-tree per class (the "same type" test of Algorithm 1 is the choice of tree).
struct PersistenceFilter::Index {
  std::map<std::string, Tree, std::less<>> trees;
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
  const double max_squared = options_.max_distance * options_.max_distance;

  // Nearest previous object of the detection's class still in its tree, within d_max.
  const auto nearest = [&](std::size_t d) -> std::optional<std::pair<double, Entry>> {
    const auto tree = index_->trees.find(detections[d].object_class);
    if (tree == index_->trees.end() || tree->second.empty()) {
      return std::nullopt;
    }
    const Point p = toPoint(detections[d].pose.translation());
    for (auto it = tree->second.qbegin(bgi::nearest(p, 1)); it != tree->second.qend(); ++it) {
      const double squared = bg::comparable_distance(p, it->first);
      if (squared <= max_squared) {
        return std::make_pair(squared, *it);
      }
    }
    return std::nullopt;
  };

  // Closest pairs first: a queue of (distance, detection, previous object).
  using Candidate = std::tuple<double, std::size_t, std::size_t>;
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> queue;
  for (std::size_t d = 0; d < detections.size(); ++d) {
    if (const auto found = nearest(d)) {
      queue.emplace(found->first, d, found->second.second);
    }
  }
  std::vector<std::optional<std::size_t>> match(detections.size());
  std::vector<bool> taken(previous.size(), false);
  while (!queue.empty()) {
    const auto [squared, d, p] = queue.top();
    queue.pop();
    if (match[d]) {
      continue;
    }
    if (taken[p]) {
      // Its nearest went to a closer detection: look again among the rest.
      if (const auto found = nearest(d)) {
        queue.emplace(found->first, d, found->second.second);
      }
      continue;
    }
    match[d] = p;
    taken[p] = true;
    index_->trees[detections[d].object_class].remove(Entry(toPoint(previous[p].pose.translation()), p));
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
    const Detection& detection = detections[d];
    TrackedObject object;
    object.object_class = detection.object_class;
    object.confidence = detection.confidence;
    object.pose = detection.pose;
    Eigen::Matrix3d reference = options_.new_object_reference;
    if (match[d]) {
      const TrackedObject& before = previous[*match[d]];
      object.name = before.name;
      object.seen = before.seen + 1;
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
  for (std::size_t i = 0; i < objects_.size(); ++i) {
    entries[objects_[i].object_class].emplace_back(toPoint(objects_[i].pose.translation()), i);
  }
  index_->trees.clear();
  for (auto& [name, values] : entries) {
    index_->trees.emplace(name, Tree(values.begin(), values.end()));
  }
  return objects_;
}

}  // namespace costar::perception
