#include "perception/object_model.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "core/json_file.h"

namespace costar::perception {

void Cloud::append(const Cloud& other, std::size_t index) {
  points.push_back(other.points[index]);
  if (!other.normals.empty()) {
    normals.push_back(other.normals[index]);
  }
  if (!other.colors.empty()) {
    colors.push_back(other.colors[index]);
  }
  if (!other.pixels.empty()) {
    pixels.push_back(other.pixels[index]);
  }
}

namespace {

bool strictlyInside(const world::Box& box, const Eigen::Vector3d& point, double tolerance) {
  return ((point - box.center).cwiseAbs() - box.half_size).maxCoeff() < -tolerance;
}

}  // namespace

Cloud sampleOuterSurface(const std::vector<world::Box>& boxes, double spacing) {
  if (spacing <= 0) {
    throw std::invalid_argument("sampleOuterSurface: the spacing must be positive");
  }
  Cloud surface;
  const double probe = std::min(spacing * 0.25, 1e-4);
  for (const world::Box& box : boxes) {
    for (int axis = 0; axis < 3; ++axis) {
      const int u_axis = (axis + 1) % 3;
      const int v_axis = (axis + 2) % 3;
      const int u_count = std::max(1, static_cast<int>(std::lround(2.0 * box.half_size[u_axis] / spacing)));
      const int v_count = std::max(1, static_cast<int>(std::lround(2.0 * box.half_size[v_axis] / spacing)));
      for (const double side : {-1.0, 1.0}) {
        Eigen::Vector3d normal = Eigen::Vector3d::Zero();
        normal[axis] = side;
        for (int i = 0; i < u_count; ++i) {
          for (int j = 0; j < v_count; ++j) {
            Eigen::Vector3d point = box.center;
            point[axis] += side * box.half_size[axis];
            point[u_axis] += box.half_size[u_axis] * (2.0 * (i + 0.5) / u_count - 1.0);
            point[v_axis] += box.half_size[v_axis] * (2.0 * (j + 0.5) / v_count - 1.0);
            // Outside the union just beyond the face: an outer surface point. A face another
            // box covers (or touches face to face) is inside the union there.
            const Eigen::Vector3d outside = point + probe * normal;
            const bool covered = std::any_of(boxes.begin(), boxes.end(), [&](const world::Box& other) {
              return strictlyInside(other, outside, 0.0) ||
                     (&other != &box && ((outside - other.center).cwiseAbs() - other.half_size).maxCoeff() <= probe);
            });
            if (!covered) {
              surface.points.push_back(point.cast<float>());
              surface.normals.push_back(normal.cast<float>());
            }
          }
        }
      }
    }
  }
  return surface;
}

std::vector<Eigen::Vector3f> sampleInterior(const std::vector<world::Box>& boxes, double spacing) {
  std::vector<Eigen::Vector3f> points;
  Eigen::AlignedBox3d bounds;
  for (const world::Box& box : boxes) {
    bounds.extend(box.center - box.half_size);
    bounds.extend(box.center + box.half_size);
  }
  const Eigen::Vector3i counts = (bounds.sizes() / spacing).array().ceil().cast<int>().max(1);
  const Eigen::Vector3d step = bounds.sizes().cwiseQuotient(counts.cast<double>());
  for (int z = 0; z < counts.z(); ++z) {
    for (int y = 0; y < counts.y(); ++y) {
      for (int x = 0; x < counts.x(); ++x) {
        const Eigen::Vector3d p = bounds.min() + step.cwiseProduct(Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5));
        if (std::any_of(boxes.begin(), boxes.end(),
                        [&](const world::Box& box) { return strictlyInside(box, p, 0.0); })) {
          points.push_back(p.cast<float>());
        }
      }
    }
  }
  return points;
}

SurfaceGrid buildSurfaceGrid(const Cloud& surface, float resolution, float margin) {
  if (surface.empty()) {
    throw std::invalid_argument("buildSurfaceGrid: no surface samples");
  }
  SurfaceGrid grid;
  grid.resolution = resolution;
  Eigen::Vector3f low = surface.points.front();
  Eigen::Vector3f high = low;
  for (const auto& p : surface.points) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  grid.origin = low - Eigen::Vector3f::Constant(margin);
  grid.dims = (((high - low).array() + 2 * margin) / resolution).ceil().cast<int>().max(1);
  const auto index = [&grid](int x, int y, int z) {
    return (static_cast<std::size_t>(z) * grid.dims.y() + y) * grid.dims.x() + x;
  };
  const auto center = [&grid](int x, int y, int z) {
    return Eigen::Vector3f(grid.origin + grid.resolution * Eigen::Vector3f(x + 0.5f, y + 0.5f, z + 0.5f));
  };
  grid.nearest.assign(static_cast<std::size_t>(grid.dims.prod()), -1);
  // Seeds: each sample claims its own cell (the nearest sample to the cell centre wins).
  for (std::size_t i = 0; i < surface.size(); ++i) {
    const Eigen::Vector3i cell = ((surface.points[i] - grid.origin) / resolution).cast<int>();
    const std::size_t at = index(cell.x(), cell.y(), cell.z());
    const int current = grid.nearest[at];
    if (current < 0 || (surface.points[i] - center(cell.x(), cell.y(), cell.z())).squaredNorm() <
                           (surface.points[current] - center(cell.x(), cell.y(), cell.z())).squaredNorm()) {
      grid.nearest[at] = static_cast<int>(i);
    }
  }
  // Jump flooding: propagate the nearest sample with halving steps, then two passes of 1.
  std::vector<int> steps;
  for (int step = std::max({grid.dims.x(), grid.dims.y(), grid.dims.z()}) / 2; step >= 1; step /= 2) {
    steps.push_back(step);
  }
  steps.push_back(1);
  steps.push_back(1);
  for (const int step : steps) {
    for (int z = 0; z < grid.dims.z(); ++z) {
      for (int y = 0; y < grid.dims.y(); ++y) {
        for (int x = 0; x < grid.dims.x(); ++x) {
          const Eigen::Vector3f c = center(x, y, z);
          int best = grid.nearest[index(x, y, z)];
          float best_distance = best < 0 ? std::numeric_limits<float>::max() : (surface.points[best] - c).squaredNorm();
          for (int dz = -step; dz <= step; dz += step) {
            for (int dy = -step; dy <= step; dy += step) {
              for (int dx = -step; dx <= step; dx += step) {
                const int nx = x + dx;
                const int ny = y + dy;
                const int nz = z + dz;
                if (nx < 0 || ny < 0 || nz < 0 || nx >= grid.dims.x() || ny >= grid.dims.y() || nz >= grid.dims.z()) {
                  continue;
                }
                const int candidate = grid.nearest[index(nx, ny, nz)];
                if (candidate < 0 || candidate == best) {
                  continue;
                }
                const float distance = (surface.points[candidate] - c).squaredNorm();
                if (distance < best_distance) {
                  best = candidate;
                  best_distance = distance;
                }
              }
            }
          }
          grid.nearest[index(x, y, z)] = best;
        }
      }
    }
  }
  return grid;
}

ObjectModel buildObjectModel(const world::ObjectClass& object_class, const ClassParameters& parameters) {
  ObjectModel model;
  model.object_class = object_class;
  model.parameters = parameters;
  const Eigen::Vector3d size = object_class.bounds().sizes();
  if (model.parameters.pair_width <= 0) {
    model.parameters.pair_width = std::max(0.02, 0.7 * size.minCoeff());
  }
  model.surface = sampleOuterSurface(object_class.boxes, model.parameters.sample_spacing);
  model.grid = buildSurfaceGrid(model.surface, 0.002f, 0.02f);
  model.interior = sampleInterior(object_class.boxes, 0.005);
  for (const auto& p : model.surface.points) {
    model.radius = std::max(model.radius, static_cast<double>(p.norm()));
  }
  return model;
}

std::vector<ObjectModel> loadObjectModels(const std::filesystem::path& objects_dir,
                                          const std::filesystem::path& classes_file) {
  const std::vector<world::ObjectClass> classes = world::loadObjectClasses(objects_dir);
  nlohmann::json json = nlohmann::json::object();
  std::ifstream stream(classes_file);
  if (!stream) {
    throw std::runtime_error("cannot open perception class parameters '" + classes_file.string() + "'");
  }
  std::map<std::string, ClassParameters> parameters;
  try {
    json = core::readJsonFile(classes_file);
    ClassParameters defaults;
    const nlohmann::json default_json = json.value("defaults", nlohmann::json::object());
    const auto read = [](const nlohmann::json& entry, ClassParameters base) {
      base.svm_label = entry.value("svm_label", base.svm_label);
      base.pair_width = entry.value("pair_width", base.pair_width);
      base.voxel_size = entry.value("voxel_size", base.voxel_size);
      base.recognition_spacing = entry.value("recognition_spacing", base.recognition_spacing);
      base.penalty_fraction = entry.value("penalty_fraction", base.penalty_fraction);
      base.sample_spacing = entry.value("sample_spacing", base.sample_spacing);
      base.relative_object_size = entry.value("relative_object_size", base.relative_object_size);
      base.visibility = entry.value("visibility", base.visibility);
      if (base.voxel_size <= 0 || base.sample_spacing <= 0 || base.recognition_spacing <= 0 || base.pair_width < 0 ||
          base.penalty_fraction <= 0 || base.penalty_fraction > 1 || base.relative_object_size <= 0 ||
          base.relative_object_size > 1 || base.visibility <= 0 || base.visibility > 1) {
        throw std::runtime_error("a size is not positive or a fraction is outside (0, 1]");
      }
      return base;
    };
    defaults = read(default_json, defaults);
    defaults.svm_label = 0;
    for (const auto& object_class : classes) {
      parameters[object_class.name] = defaults;
    }
    const nlohmann::json class_entries = json.value("classes", nlohmann::json::object());
    for (const auto& [name, entry] : class_entries.items()) {
      if (!parameters.contains(name)) {
        throw std::runtime_error("an entry for class '" + name + "', which " + objects_dir.string() + " lacks");
      }
      parameters[name] = read(entry, defaults);
    }
  } catch (const std::exception& e) {
    throw std::runtime_error("perception class parameters '" + classes_file.string() + "': " + e.what());
  }
  // Labels: as given, else the next free ones in name order.
  std::set<int> used;
  for (const auto& [name, p] : parameters) {
    if (p.svm_label < 0) {
      throw std::runtime_error("perception class parameters '" + classes_file.string() + "': class '" + name +
                               "' has a negative svm_label (0 is the background)");
    }
    if (p.svm_label > 0 && !used.insert(p.svm_label).second) {
      throw std::runtime_error("perception class parameters '" + classes_file.string() + "': svm_label " +
                               std::to_string(p.svm_label) + " is given to two classes");
    }
  }
  int next = 1;
  std::vector<ObjectModel> models;
  for (const auto& object_class : classes) {
    ClassParameters p = parameters.at(object_class.name);
    if (p.svm_label == 0) {
      while (used.contains(next)) {
        ++next;
      }
      p.svm_label = next;
      used.insert(next);
    }
    models.push_back(buildObjectModel(object_class, p));
  }
  return models;
}

}  // namespace costar::perception
