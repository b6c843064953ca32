#include "perception/svm_classifier.h"

#include <svm.h>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

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

#include "core/files.h"
#include "core/json_file.h"

namespace costar::perception {

namespace {

void quiet(const char*) {}

/// libsvm's rand() based fold assignment needs one seed at a time.
std::mutex libsvm_mutex;

/// The AVX2 path keeps every class pair's sums in registers: up to 8 pairs (5 classes).
constexpr int kMaxVectorPairs = 8;

#if defined(__x86_64__) && defined(__GNUC__)

bool avx2Available() {
  static const bool available = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return available;
}

// The AVX2 path. Only intrinsics and plain loops here (no inline functions shared with other
// translation units), so that no AVX2 code can stand in for a portable copy elsewhere.

/// exp(v) for v <= 0, 8 at a time (Cephes' expf: 2^n times a degree-6 polynomial on
/// [-ln2/2, ln2/2]; relative error about 2e-7); below -87.3 it gives about 1e-38.
__attribute__((target("avx2,fma"))) inline __m256 expNonPositive(__m256 v) {
  v = _mm256_max_ps(v, _mm256_set1_ps(-87.3f));
  const __m256 n = _mm256_floor_ps(_mm256_fmadd_ps(v, _mm256_set1_ps(1.44269504088896341f), _mm256_set1_ps(0.5f)));
  __m256 r = _mm256_fnmadd_ps(n, _mm256_set1_ps(0.693359375f), v);
  r = _mm256_fnmadd_ps(n, _mm256_set1_ps(-2.12194440e-4f), r);
  __m256 y = _mm256_set1_ps(1.9875691500e-4f);
  y = _mm256_fmadd_ps(y, r, _mm256_set1_ps(1.3981999507e-3f));
  y = _mm256_fmadd_ps(y, r, _mm256_set1_ps(8.3334519073e-3f));
  y = _mm256_fmadd_ps(y, r, _mm256_set1_ps(4.1665795894e-2f));
  y = _mm256_fmadd_ps(y, r, _mm256_set1_ps(1.6666665459e-1f));
  y = _mm256_fmadd_ps(y, r, _mm256_set1_ps(5.0000001201e-1f));
  y = _mm256_fmadd_ps(y, _mm256_mul_ps(r, r), _mm256_add_ps(r, _mm256_set1_ps(1.0f)));
  const __m256i exponent = _mm256_slli_epi32(_mm256_add_epi32(_mm256_cvtps_epi32(n), _mm256_set1_epi32(127)), 23);
  return _mm256_mul_ps(y, _mm256_castsi256_ps(exponent));
}

/// sums(r, p) = sum_s coefficients(p, s) exp(-gamma max(0, |x_r|^2 + |s|^2 - 2 x_r . s)) for
/// `rows` rows of `x` (row-major, `dims` each) against `padded` support vectors (feature-major;
/// padded to a multiple of 8 with zero coefficients). Four rows share each load of the support
/// vectors; the pairs' sums (at most 8) stay in registers.
__attribute__((target("avx2,fma"))) void rbfDecisionsAvx2(const float* x, const float* x_norms, int rows, int dims,
                                                          const float* support, const float* support_norms,
                                                          const float* coefficients, int padded, int pairs, float gamma,
                                                          float* sums) {
  constexpr int kRows = 4;
  constexpr int kMaxPairs = kMaxVectorPairs;
  const __m256 minus_gamma = _mm256_set1_ps(-gamma);
  const __m256 minus_two = _mm256_set1_ps(-2.0f);
  const __m256 zero = _mm256_setzero_ps();
  for (int r0 = 0; r0 < rows; r0 += kRows) {
    const int block = rows - r0 < kRows ? rows - r0 : kRows;
    __m256 total[kRows][kMaxPairs];
    for (int i = 0; i < kRows; ++i) {
      for (int p = 0; p < kMaxPairs; ++p) {
        total[i][p] = zero;
      }
    }
    for (int s = 0; s < padded; s += 8) {
      __m256 dot[kRows] = {zero, zero, zero, zero};
      for (int f = 0; f < dims; ++f) {
        const __m256 column = _mm256_loadu_ps(support + static_cast<long>(f) * padded + s);
        for (int i = 0; i < block; ++i) {
          dot[i] = _mm256_fmadd_ps(_mm256_set1_ps(x[static_cast<long>(r0 + i) * dims + f]), column, dot[i]);
        }
      }
      const __m256 norms = _mm256_loadu_ps(support_norms + s);
      for (int i = 0; i < block; ++i) {
        __m256 distance = _mm256_fmadd_ps(minus_two, dot[i], _mm256_add_ps(norms, _mm256_set1_ps(x_norms[r0 + i])));
        distance = _mm256_max_ps(distance, zero);
        const __m256 kernel = expNonPositive(_mm256_mul_ps(distance, minus_gamma));
        for (int p = 0; p < pairs; ++p) {
          total[i][p] =
              _mm256_fmadd_ps(kernel, _mm256_loadu_ps(coefficients + static_cast<long>(p) * padded + s), total[i][p]);
        }
      }
    }
    for (int i = 0; i < block; ++i) {
      for (int p = 0; p < pairs; ++p) {
        alignas(32) float lanes[8];
        _mm256_store_ps(lanes, total[i][p]);
        sums[static_cast<long>(r0 + i) * pairs + p] =
            ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) + ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7]));
      }
    }
  }
}
#else
bool avx2Available() { return false; }
void rbfDecisionsAvx2(const float*, const float*, int, int, const float*, const float*, const float*, int, int, float,
                      float*) {}
#endif

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
  std::map<int, std::vector<int>> held_out_of;  // per label, examples not trained on
  for (auto& [label, rows] : rows_of) {
    std::shuffle(rows.begin(), rows.end(), random);
    if (options.max_per_label > 0 && static_cast<int>(rows.size()) > options.max_per_label) {
      const std::size_t keep = static_cast<std::size_t>(options.max_per_label);
      const std::size_t held = std::min(rows.size() - keep, static_cast<std::size_t>(options.held_out_per_label));
      held_out_of[label].assign(rows.begin() + static_cast<std::ptrdiff_t>(keep),
                                rows.begin() + static_cast<std::ptrdiff_t>(keep + held));
      rows.resize(keep);
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
  classifier.prepareKernel();
  int held_total = 0;
  int held_correct = 0;
  for (const auto& [label, held] : held_out_of) {
    if (held.empty()) {
      continue;
    }
    say("classifying " + std::to_string(held.size()) + " held-out " + names.at(label) + " examples");
    Eigen::MatrixXf rows_held(static_cast<Eigen::Index>(held.size()), dims);
    for (std::size_t i = 0; i < held.size(); ++i) {
      rows_held.row(static_cast<Eigen::Index>(i)) = features.row(held[i]);
    }
    const std::vector<int> predicted = classifier.predict(rows_held);
    auto& entry = local.labels[label];
    entry.held_out = static_cast<int>(held.size());
    entry.held_out_correct = static_cast<int>(std::count(predicted.begin(), predicted.end(), label));
    held_total += entry.held_out;
    held_correct += entry.held_out_correct;
  }
  local.held_out_accuracy = held_total == 0 ? 0.0 : static_cast<double>(held_correct) / held_total;
  local.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  classifier.report_ = local;
  if (report != nullptr) {
    *report = local;
  }
  return classifier;
}

Eigen::MatrixXf SvmClassifier::decisionValues(const Eigen::MatrixXf& features, Instructions instructions) const {
  if (features.cols() != mean_.size()) {
    throw std::invalid_argument("SvmClassifier::predict: expected " + std::to_string(mean_.size()) +
                                " features per row, got " + std::to_string(features.cols()));
  }
  const Eigen::Index n = features.rows();
  const auto pairs = static_cast<Eigen::Index>(rho_.size());
  if (n == 0 || empty()) {
    return Eigen::MatrixXf::Zero(n, pairs);
  }
  // Standardized, row-major: each row's features contiguous for the vector path.
  using RowMajor = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMajor x = (features.rowwise() - mean_.transpose()).array().rowwise() / scale_.transpose().array();
  Eigen::MatrixXf decisions(n, pairs);
  if (instructions == Instructions::kBest && vectorKernelAvailable() && padded_count_ > 0 && pairs <= kMaxVectorPairs) {
    const Eigen::VectorXf x_norms = x.rowwise().squaredNorm();
    RowMajor sums(n, pairs);
    rbfDecisionsAvx2(x.data(), x_norms.data(), static_cast<int>(n), static_cast<int>(x.cols()),
                     support_by_feature_.data(), support_norms_.data(), coefficients_by_pair_.data(), padded_count_,
                     static_cast<int>(pairs), gamma_, sums.data());
    decisions = sums;
  } else {
    // K = exp(-gamma |x - s|^2), from the squared norms and one product.
    const Eigen::MatrixXf by_column = x;
    const Eigen::VectorXf s_norms = support_vectors_.rowwise().squaredNorm();
    Eigen::MatrixXf kernel = by_column * support_vectors_.transpose();
    kernel = ((-2.0f * kernel).colwise() + by_column.rowwise().squaredNorm()).rowwise() + s_norms.transpose();
    kernel = (kernel.array().max(0.0f) * -gamma_).exp().matrix();
    decisions = kernel * coefficients_;  // n x pairs
  }
  decisions.rowwise() -= rho_.transpose();
  return decisions;
}

bool SvmClassifier::vectorKernelAvailable() { return avx2Available(); }

void SvmClassifier::prepareKernel() {
  const auto count = static_cast<int>(support_vectors_.rows());
  const auto dims = static_cast<int>(support_vectors_.cols());
  const auto pairs = static_cast<int>(coefficients_.cols());
  padded_count_ = (count + 7) / 8 * 8;
  const auto padded = static_cast<std::size_t>(padded_count_);
  support_by_feature_.assign(static_cast<std::size_t>(dims) * padded, 0.0f);
  support_norms_.assign(padded, 0.0f);
  coefficients_by_pair_.assign(static_cast<std::size_t>(pairs) * padded, 0.0f);
  for (int s = 0; s < count; ++s) {
    for (int f = 0; f < dims; ++f) {
      support_by_feature_[static_cast<std::size_t>(f) * padded + static_cast<std::size_t>(s)] = support_vectors_(s, f);
    }
    support_norms_[static_cast<std::size_t>(s)] = support_vectors_.row(s).squaredNorm();
    for (int p = 0; p < pairs; ++p) {
      coefficients_by_pair_[static_cast<std::size_t>(p) * padded + static_cast<std::size_t>(s)] = coefficients_(s, p);
    }
  }
}

std::vector<int> SvmClassifier::predict(const Eigen::MatrixXf& features, Instructions instructions) const {
  const Eigen::MatrixXf decisions = decisionValues(features, instructions);
  const Eigen::Index n = features.rows();
  std::vector<int> out(static_cast<std::size_t>(n), labels_.empty() ? 0 : labels_.front());
  if (n == 0 || empty()) {
    return out;
  }
  const int classes = static_cast<int>(labels_.size());
  std::vector<int> votes(static_cast<std::size_t>(classes));
  for (Eigen::Index r = 0; r < n; ++r) {
    std::fill(votes.begin(), votes.end(), 0);
    int p = 0;
    for (int i = 0; i < classes; ++i) {
      for (int j = i + 1; j < classes; ++j, ++p) {
        if (decisions(r, p) > 0) {
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
  training["held_out_accuracy"] = report_.held_out_accuracy;
  training["folds"] = report_.folds;
  training["support_vectors"] = report_.support_vectors;
  for (const auto& [label, entry] : report_.labels) {
    training["labels"][std::to_string(label)] = {{"name", entry.name},
                                                 {"examples", entry.examples},
                                                 {"cross_validated_accuracy", entry.accuracy()},
                                                 {"held_out_examples", entry.held_out},
                                                 {"held_out_accuracy", entry.heldOutAccuracy()}};
  }
  json["training"] = training;
  writeOutputFile(file, json.dump() + "\n");
}

SvmClassifier SvmClassifier::load(const std::filesystem::path& file) {
  std::ifstream stream(file);
  if (!stream) {
    throw std::runtime_error("cannot open the SVM model '" + file.string() +
                             "' (train one with `costar perception train`)");
  }
  try {
    const nlohmann::json json = core::readJsonFile(file);
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
      classifier.report_.held_out_accuracy = training.value("held_out_accuracy", 0.0);
      classifier.report_.folds = training.value("folds", 0);
      classifier.report_.support_vectors = training.value("support_vectors", 0);
      const nlohmann::json per_label = training.value("labels", nlohmann::json::object());
      for (const auto& [label, entry] : per_label.items()) {
        auto& out = classifier.report_.labels[std::stoi(label)];
        out.name = entry.value("name", "");
        out.examples = entry.value("examples", 0);
        out.correct = static_cast<int>(std::lround(entry.value("cross_validated_accuracy", 0.0) * out.examples));
        out.held_out = entry.value("held_out_examples", 0);
        out.held_out_correct = static_cast<int>(std::lround(entry.value("held_out_accuracy", 0.0) * out.held_out));
      }
    }
    classifier.prepareKernel();
    return classifier;
  } catch (const std::exception& e) {
    throw std::runtime_error("SVM model '" + file.string() + "': " + e.what());
  }
}

}  // namespace costar::perception
