#include "perception/persistence.h"

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/box.hpp>
#include <boost/geometry/geometries/point.hpp>
#include <boost/geometry/index/rtree.hpp>

#include <algorithm>
#include <map>
#include <optional>
#include <span>
#include <thread>
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

/// From this many detections on, the queries, the objects' poses and the next trees are made on
/// two threads (below it a thread costs more than it saves; a scene has a handful of parts).
constexpr std::size_t kParallelFrom = 2048;

/// Runs `work(begin, end)` over [0, count): on two threads (the calling one and one more) when
/// `parallel`, else on the calling one. The halves are the same for a given count.
template <typename Work>
void inHalves(std::size_t count, bool parallel, const Work& work) {
  if (!parallel) {
    work(std::size_t{0}, count);
    return;
  }
  std::thread second(work, count / 2, count);
  work(std::size_t{0}, count / 2);
  second.join();
}

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
  const bool parallel = detections.size() >= kParallelFrom;
  // Each half of the detections collects its pairs; the first half's then the second's is the
  // detections' order, as one pass would give.
  std::vector<Pair> pairs;
  std::vector<Pair> second_pairs;
  pairs.reserve(detections.size());
  std::vector<Entry>& hits = index_->hits;
  std::vector<Entry> second_hits;
  inHalves(detections.size(), parallel, [&](std::size_t begin, std::size_t end) {
    std::vector<Pair>& found = begin == 0 ? pairs : second_pairs;
    std::vector<Entry>& buffer = begin == 0 ? hits : second_hits;
    const Tree* tree = nullptr;
    const std::string* tree_class = nullptr;
    for (std::size_t d = begin; d < end; ++d) {
      const std::string& object_class = detections[d].object_class;
      if (tree_class == nullptr || *tree_class != object_class) {
        const auto tree_found = index_->trees.find(object_class);
        tree = tree_found == index_->trees.end() ? nullptr : &tree_found->second;
        tree_class = &object_class;
      }
      if (tree == nullptr || tree->empty()) {
        continue;
      }
      const Point p = toPoint(detections[d].pose.translation());
      const Box around(Point(p.get<0>() - max_distance, p.get<1>() - max_distance, p.get<2>() - max_distance),
                       Point(p.get<0>() + max_distance, p.get<1>() + max_distance, p.get<2>() + max_distance));
      buffer.clear();
      tree->query(bgi::intersects(around), std::back_inserter(buffer));
      for (const Entry& hit : buffer) {
        const double squared = bg::comparable_distance(p, hit.first);
        if (squared <= max_squared) {
          found.push_back({squared, static_cast<std::uint32_t>(d), static_cast<std::uint32_t>(hit.second)});
        }
      }
    }
  });
  pairs.insert(pairs.end(), second_pairs.begin(), second_pairs.end());
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
  // Fresh names first, in the detections' order (the counters count up); then each object,
  // its canonical orientation included, on its own (two threads for many).
  objects_.resize(detections.size());
  for (std::size_t d = 0; d < detections.size(); ++d) {
    if (!match[d]) {
      const std::string& object_class = detections[d].object_class;
      auto counter = std::find_if(counters_.begin(), counters_.end(),
                                  [&](const auto& entry) { return entry.first == object_class; });
      if (counter == counters_.end()) {
        counters_.emplace_back(object_class, 0);
        counter = counters_.end() - 1;
      }
      objects_[d].name = object_class + "_" + std::to_string(++counter->second);
    }
  }
  inHalves(detections.size(), parallel, [&](std::size_t begin, std::size_t end) {
    for (std::size_t d = begin; d < end; ++d) {
      // The matched previous objects are read in the detections' order, scattered over memory:
      // ask for the one a few detections ahead now, so it is in the cache when it is read.
      if (const std::size_t ahead = d + kPrefetchAhead; ahead < end && match[ahead]) {
        const auto* bytes = reinterpret_cast<const char*>(&previous[*match[ahead]]);
        for (std::size_t offset = 0; offset < sizeof(TrackedObject); offset += 64) {
          __builtin_prefetch(bytes + offset);
        }
      }
      const Detection& detection = detections[d];
      TrackedObject& object = objects_[d];
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
        object.seen = 1;
      }
      if (options_.canonical_orientation) {
        if (const world::ObjectClass* object_class = find_class(detection.object_class)) {
          object.pose = setCanonicalOrientation(object.pose, *object_class, reference).pose;
        }
      }
    }
  });
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
  // The trees are independent: the classes split over two threads for many objects.
  index_->trees.clear();
  std::vector<std::pair<std::vector<Entry>*, Tree*>> builds;
  for (auto& [name, values] : entries) {
    builds.emplace_back(&values, &index_->trees.emplace(name, Tree()).first->second);
  }
  inHalves(builds.size(), parallel && builds.size() > 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t b = begin; b < end; ++b) {
      *builds[b].second = Tree(builds[b].first->begin(), builds[b].first->end());
    }
  });
  return objects_;
}

}  // namespace costar::perception
