#include "perception/svm_classifier.h"

#include <svm.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <stdexcept>

namespace costar::perception {

namespace {

void quiet(const char*) {}

/// libsvm's rand() based fold assignment needs one seed at a time.
std::mutex libsvm_mutex;

}  // namespace

int SvmClassifier::labelOf(const std::string& name) const {
  for (const auto& [label, label_name] : names_) {
    if (label_name == name) {
      return label;
    }
  }
  return -1;
}

SvmClassifier SvmClassifier::train(const Eigen::MatrixXf& features, const std::vector<int>& labels,
                                   const std::map<int, std::string>& names, const SvmTrainingOptions& options,
                                   SvmTrainingReport* report, const std::function<void(const std::string&)>& progress) {
  const auto say = [&progress](const std::string& text) {
    if (progress) {
      progress(text);
    }
  };
  const auto start = std::chrono::steady_clock::now();
  if (static_cast<std::size_t>(features.rows()) != labels.size() || features.rows() == 0 || features.cols() == 0) {
    throw std::invalid_argument("SvmClassifier::train: one label per row of features is needed");
  }
  std::map<int, std::vector<int>> rows_of;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] < 0) {
      throw std::invalid_argument("SvmClassifier::train: labels must not be negative");
    }
    rows_of[labels[i]].push_back(static_cast<int>(i));
  }
  if (rows_of.size() < 2) {
    throw std::invalid_argument("SvmClassifier::train: at least two labels are needed");
  }
  for (const auto& [label, rows] : rows_of) {
    if (!names.contains(label)) {
      throw std::invalid_argument("SvmClassifier::train: label " + std::to_string(label) + " has no name");
    }
  }
  // Balanced subsample, in a fixed order.
  std::mt19937 random(options.seed);
  std::vector<int> chosen;
  for (auto& [label, rows] : rows_of) {
    std::shuffle(rows.begin(), rows.end(), random);
    if (options.max_per_label > 0 && static_cast<int>(rows.size()) > options.max_per_label) {
      rows.resize(static_cast<std::size_t>(options.max_per_label));
    }
    std::sort(rows.begin(), rows.end());
    chosen.insert(chosen.end(), rows.begin(), rows.end());
  }
  std::sort(chosen.begin(), chosen.end());
  const int count = static_cast<int>(chosen.size());
  const int dims = static_cast<int>(features.cols());

  SvmClassifier classifier;
  classifier.names_ = names;
  // Standardization from the chosen examples.
  Eigen::MatrixXf data(count, dims);
  for (int i = 0; i < count; ++i) {
    data.row(i) = features.row(chosen[static_cast<std::size_t>(i)]);
  }
  classifier.mean_ = data.colwise().mean().transpose();
  classifier.scale_ =
      ((data.rowwise() - classifier.mean_.transpose()).array().square().colwise().sum() / std::max(1, count - 1))
          .sqrt()
          .transpose();
  for (int d = 0; d < dims; ++d) {
    if (!(classifier.scale_[d] > 1e-6f)) {
      classifier.scale_[d] = 1.0f;
    }
  }
  data = (data.rowwise() - classifier.mean_.transpose()).array().rowwise() / classifier.scale_.transpose().array();

  // libsvm's problem.
  std::vector<svm_node> nodes(static_cast<std::size_t>(count) * (dims + 1));
  std::vector<svm_node*> rows(static_cast<std::size_t>(count));
  std::vector<double> targets(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    svm_node* row = &nodes[static_cast<std::size_t>(i) * (dims + 1)];
    for (int d = 0; d < dims; ++d) {
      row[d] = {d + 1, static_cast<double>(data(i, d))};
    }
    row[dims] = {-1, 0.0};
    rows[static_cast<std::size_t>(i)] = row;
    targets[static_cast<std::size_t>(i)] = labels[static_cast<std::size_t>(chosen[static_cast<std::size_t>(i)])];
  }
  svm_problem problem{count, targets.data(), rows.data()};
  svm_parameter parameter{};
  parameter.svm_type = C_SVC;
  parameter.kernel_type = RBF;
  parameter.gamma = options.gamma > 0 ? options.gamma : 1.0 / dims;
  parameter.C = options.cost;
  parameter.cache_size = 200;
  parameter.eps = 1e-3;
  parameter.shrinking = 1;
  parameter.probability = 0;
  parameter.nr_weight = 0;
  std::lock_guard lock(libsvm_mutex);
  svm_set_print_string_function(&quiet);
  if (const char* problem_text = svm_check_parameter(&problem, &parameter)) {
    throw std::invalid_argument(std::string("libsvm: ") + problem_text);
  }

  SvmTrainingReport local;
  for (const auto& [label, label_rows] : rows_of) {
    local.labels[label].name = names.at(label);
  }
  if (options.folds >= 2) {
    say("cross-validating (" + std::to_string(options.folds) + " folds, " + std::to_string(count) + " examples)");
    std::srand(options.seed);
    std::vector<double> predicted(static_cast<std::size_t>(count));
    svm_cross_validation(&problem, &parameter, options.folds, predicted.data());
    int correct = 0;
    for (int i = 0; i < count; ++i) {
      auto& entry = local.labels[static_cast<int>(targets[static_cast<std::size_t>(i)])];
      ++entry.examples;
      if (predicted[static_cast<std::size_t>(i)] == targets[static_cast<std::size_t>(i)]) {
        ++entry.correct;
        ++correct;
      }
    }
    local.overall_accuracy = static_cast<double>(correct) / count;
    local.folds = options.folds;
  } else {
    for (int i = 0; i < count; ++i) {
      ++local.labels[static_cast<int>(targets[static_cast<std::size_t>(i)])].examples;
    }
  }
  say("training the final model on " + std::to_string(count) + " examples");
  svm_model* model = svm_train(&problem, &parameter);
  const int classes = model->nr_class;
  classifier.gamma_ = static_cast<float>(parameter.gamma);
  classifier.labels_.assign(model->label, model->label + classes);
  classifier.support_counts_.assign(model->nSV, model->nSV + classes);
  const int total = model->l;
  classifier.support_vectors_.resize(total, dims);
  for (int s = 0; s < total; ++s) {
    classifier.support_vectors_.row(s).setZero();
    for (const svm_node* node = model->SV[s]; node->index != -1; ++node) {
      classifier.support_vectors_(s, node->index - 1) = static_cast<float>(node->value);
    }
  }
  // Coefficient matrix: support vector x class pair, in libsvm's pair order.
  const int pairs = classes * (classes - 1) / 2;
  classifier.coefficients_.setZero(total, pairs);
  classifier.rho_.resize(pairs);
  std::vector<int> first(static_cast<std::size_t>(classes), 0);
  for (int c = 1; c < classes; ++c) {
    first[static_cast<std::size_t>(c)] = first[static_cast<std::size_t>(c - 1)] + model->nSV[c - 1];
  }
  int p = 0;
  for (int i = 0; i < classes; ++i) {
    for (int j = i + 1; j < classes; ++j, ++p) {
      for (int k = 0; k < model->nSV[i]; ++k) {
        const int s = first[static_cast<std::size_t>(i)] + k;
        classifier.coefficients_(s, p) = static_cast<float>(model->sv_coef[j - 1][s]);
      }
      for (int k = 0; k < model->nSV[j]; ++k) {
        const int s = first[static_cast<std::size_t>(j)] + k;
        classifier.coefficients_(s, p) = static_cast<float>(model->sv_coef[i][s]);
      }
      classifier.rho_[p] = static_cast<float>(model->rho[p]);
    }
  }
  svm_free_and_destroy_model(&model);
  local.support_vectors = total;
  local.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  classifier.report_ = local;
  if (report != nullptr) {
    *report = local;
  }
  return classifier;
}

std::vector<int> SvmClassifier::predict(const Eigen::MatrixXf& features) const {
  if (features.cols() != mean_.size()) {
    throw std::invalid_argument("SvmClassifier::predict: expected " + std::to_string(mean_.size()) +
                                " features per row, got " + std::to_string(features.cols()));
  }
  const Eigen::Index n = features.rows();
  std::vector<int> out(static_cast<std::size_t>(n), labels_.empty() ? 0 : labels_.front());
  if (n == 0 || empty()) {
    return out;
  }
  const Eigen::MatrixXf x = (features.rowwise() - mean_.transpose()).array().rowwise() / scale_.transpose().array();
  // K = exp(-gamma |x - s|^2), from the squared norms and one product.
  const Eigen::VectorXf x_norms = x.rowwise().squaredNorm();
  const Eigen::VectorXf s_norms = support_vectors_.rowwise().squaredNorm();
  Eigen::MatrixXf kernel = x * support_vectors_.transpose();
  kernel = ((-2.0f * kernel).colwise() + x_norms).rowwise() + s_norms.transpose();
  kernel = (kernel.array().max(0.0f) * -gamma_).exp().matrix();
  const Eigen::MatrixXf decisions = kernel * coefficients_;  // n x pairs
  const int classes = static_cast<int>(labels_.size());
  std::vector<int> votes(static_cast<std::size_t>(classes));
  for (Eigen::Index r = 0; r < n; ++r) {
    std::fill(votes.begin(), votes.end(), 0);
    int p = 0;
    for (int i = 0; i < classes; ++i) {
      for (int j = i + 1; j < classes; ++j, ++p) {
        if (decisions(r, p) - rho_[p] > 0) {
          ++votes[static_cast<std::size_t>(i)];
        } else {
          ++votes[static_cast<std::size_t>(j)];
        }
      }
    }
    const auto best = std::max_element(votes.begin(), votes.end()) - votes.begin();
    out[static_cast<std::size_t>(r)] = labels_[static_cast<std::size_t>(best)];
  }
  return out;
}

namespace {

nlohmann::json matrixToJson(const Eigen::MatrixXf& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    std::vector<float> row(static_cast<std::size_t>(m.cols()));
    for (Eigen::Index c = 0; c < m.cols(); ++c) {
      row[static_cast<std::size_t>(c)] = m(r, c);
    }
    rows.push_back(row);
  }
  return rows;
}

Eigen::MatrixXf matrixFromJson(const nlohmann::json& json, Eigen::Index cols) {
  Eigen::MatrixXf m(static_cast<Eigen::Index>(json.size()), cols);
  for (std::size_t r = 0; r < json.size(); ++r) {
    const auto& row = json[r];
    if (static_cast<Eigen::Index>(row.size()) != cols) {
      throw std::runtime_error("a matrix row has " + std::to_string(row.size()) + " values, expected " +
                               std::to_string(cols));
    }
    for (Eigen::Index c = 0; c < cols; ++c) {
      m(static_cast<Eigen::Index>(r), c) = row[static_cast<std::size_t>(c)].get<float>();
    }
  }
  return m;
}

Eigen::VectorXf vectorFromJson(const nlohmann::json& json) {
  Eigen::VectorXf v(static_cast<Eigen::Index>(json.size()));
  for (std::size_t i = 0; i < json.size(); ++i) {
    v[static_cast<Eigen::Index>(i)] = json[i].get<float>();
  }
  return v;
}

}  // namespace

void SvmClassifier::save(const std::filesystem::path& file) const {
  nlohmann::json json;
  json["format"] = "costar-svm-rbf-1";
  json["labels"] = labels_;
  nlohmann::json names = nlohmann::json::object();
  for (const auto& [label, name] : names_) {
    names[std::to_string(label)] = name;
  }
  json["names"] = names;
  json["gamma"] = gamma_;
  json["mean"] = std::vector<float>(mean_.data(), mean_.data() + mean_.size());
  json["scale"] = std::vector<float>(scale_.data(), scale_.data() + scale_.size());
  json["support_counts"] = support_counts_;
  json["rho"] = std::vector<float>(rho_.data(), rho_.data() + rho_.size());
  json["support_vectors"] = matrixToJson(support_vectors_);
  json["coefficients"] = matrixToJson(coefficients_);
  nlohmann::json training;
  training["overall_accuracy"] = report_.overall_accuracy;
  training["folds"] = report_.folds;
  training["support_vectors"] = report_.support_vectors;
  for (const auto& [label, entry] : report_.labels) {
    training["labels"][std::to_string(label)] = {
        {"name", entry.name}, {"examples", entry.examples}, {"cross_validated_accuracy", entry.accuracy()}};
  }
  json["training"] = training;
  std::ofstream stream(file);
  if (!stream) {
    throw std::runtime_error("cannot write the SVM model '" + file.string() + "'");
  }
  stream << json.dump() << "\n";
  if (!stream) {
    throw std::runtime_error("cannot write the SVM model '" + file.string() + "'");
  }
}

SvmClassifier SvmClassifier::load(const std::filesystem::path& file) {
  std::ifstream stream(file);
  if (!stream) {
    throw std::runtime_error("cannot open the SVM model '" + file.string() +
                             "' (train one with `costar perception train`)");
  }
  try {
    const nlohmann::json json = nlohmann::json::parse(stream);
    if (json.value("format", "") != "costar-svm-rbf-1") {
      throw std::runtime_error("not a costar SVM model (format costar-svm-rbf-1)");
    }
    SvmClassifier classifier;
    classifier.labels_ = json.at("labels").get<std::vector<int>>();
    for (const auto& [label, name] : json.at("names").items()) {
      classifier.names_[std::stoi(label)] = name.get<std::string>();
    }
    classifier.gamma_ = json.at("gamma").get<float>();
    classifier.mean_ = vectorFromJson(json.at("mean"));
    classifier.scale_ = vectorFromJson(json.at("scale"));
    classifier.support_counts_ = json.at("support_counts").get<std::vector<int>>();
    classifier.rho_ = vectorFromJson(json.at("rho"));
    const Eigen::Index dims = classifier.mean_.size();
    classifier.support_vectors_ = matrixFromJson(json.at("support_vectors"), dims);
    const int classes = static_cast<int>(classifier.labels_.size());
    const int pairs = classes * (classes - 1) / 2;
    classifier.coefficients_ = matrixFromJson(json.at("coefficients"), pairs);
    if (classes < 2 || classifier.scale_.size() != dims || classifier.rho_.size() != pairs ||
        static_cast<int>(classifier.support_counts_.size()) != classes ||
        classifier.coefficients_.rows() != classifier.support_vectors_.rows()) {
      throw std::runtime_error("inconsistent sizes");
    }
    for (const int label : classifier.labels_) {
      if (!classifier.names_.contains(label)) {
        throw std::runtime_error("label " + std::to_string(label) + " has no name");
      }
    }
    if (json.contains("training")) {
      const auto& training = json.at("training");
      classifier.report_.overall_accuracy = training.value("overall_accuracy", 0.0);
      classifier.report_.folds = training.value("folds", 0);
      classifier.report_.support_vectors = training.value("support_vectors", 0);
      const nlohmann::json per_label = training.value("labels", nlohmann::json::object());
      for (const auto& [label, entry] : per_label.items()) {
        auto& out = classifier.report_.labels[std::stoi(label)];
        out.name = entry.value("name", "");
        out.examples = entry.value("examples", 0);
        out.correct = static_cast<int>(std::lround(entry.value("cross_validated_accuracy", 0.0) * out.examples));
      }
    }
    return classifier;
  } catch (const std::exception& e) {
    throw std::runtime_error("SVM model '" + file.string() + "': " + e.what());
  }
}

}  // namespace costar::perception
