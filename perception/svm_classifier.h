#pragma once
// The SVM of the segmentation stage: a C-SVC with an RBF kernel trained by libsvm
// (Chang & Lin), one-vs-one over the labels (0 = background, then one per object class).
// Features are standardized (per-feature mean and scale from the training data). Prediction
// evaluates the trained model densely with Eigen, which gives libsvm's own answers (checked
// by a unit test) at a fraction of the cost. The model file is JSON: labels and class names,
// standardization, support vectors and coefficients, and the training report.

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace costar::perception {

struct SvmTrainingOptions {
  /// Soft-margin cost.
  double cost = 30.0;
  /// RBF width on standardized features; 0 means 1 / number of features. The defaults were
  /// chosen by cross-validation on the collected examples (docs/PERCEPTION.md).
  double gamma = 0.015;
  /// Folds of the cross-validation that estimates the accuracy (0 or 1: none).
  int folds = 5;
  /// Seed of the cross-validation's fold assignment and of the subsampling below.
  unsigned seed = 1;
  /// At most this many training examples per label, drawn at random (keeps training and the
  /// number of support vectors, hence prediction time, bounded). 0: all.
  int max_per_label = 2000;
  /// After training, the model classifies up to this many examples per label that it was not
  /// trained on (drawn at random from those left out by max_per_label): the held-out accuracy.
  /// 0: none.
  int held_out_per_label = 5000;
};

/// What training measured: per label, how many examples, and the cross-validated fraction
/// classified correctly (recall).
struct SvmTrainingReport {
  struct PerLabel {
    std::string name;
    int examples = 0;
    int correct = 0;
    int held_out = 0;  // examples left out of the training, classified by the final model
    int held_out_correct = 0;
    double accuracy() const { return examples == 0 ? 0.0 : static_cast<double>(correct) / examples; }
    double heldOutAccuracy() const { return held_out == 0 ? 0.0 : static_cast<double>(held_out_correct) / held_out; }
  };
  std::map<int, PerLabel> labels;
  double overall_accuracy = 0.0;
  double held_out_accuracy = 0.0;  // over every held-out example
  int support_vectors = 0;
  int folds = 0;
  double seconds = 0.0;
};

class SvmClassifier {
 public:
  SvmClassifier() = default;

  /// Trains on `features` (one example per row) with `labels` (>= 0); `names` names each label
  /// (for files and reports). `progress` (may be empty) hears about the long steps.
  /// @throws std::invalid_argument for mismatched sizes, fewer than two labels, or a label
  /// without a name.
  static SvmClassifier train(const Eigen::MatrixXf& features, const std::vector<int>& labels,
                             const std::map<int, std::string>& names, const SvmTrainingOptions& options = {},
                             SvmTrainingReport* report = nullptr,
                             const std::function<void(const std::string&)>& progress = {});

  /// @throws std::runtime_error naming the file and the problem.
  static SvmClassifier load(const std::filesystem::path& file);
  /// Writes the model (and the training report, if any) as JSON. @throws std::runtime_error.
  void save(const std::filesystem::path& file) const;

  bool empty() const { return support_vectors_.rows() == 0; }
  int featureCount() const { return static_cast<int>(mean_.size()); }
  const std::vector<int>& labels() const { return labels_; }
  const std::map<int, std::string>& names() const { return names_; }
  /// The label named `name`, or -1.
  int labelOf(const std::string& name) const;
  int supportVectorCount() const { return static_cast<int>(support_vectors_.rows()); }
  const SvmTrainingReport& report() const { return report_; }

  /// How the RBF kernel is evaluated: kBest uses AVX2 and FMA where the CPU has them (one
  /// fused pass: dot products, exponentials and the weighted sums, 8 support vectors at a time),
  /// else the portable path (Eigen's matrix products; the same decisions to float rounding).
  enum class Instructions { kBest, kPortable };

  /// The label of each row of `features` (raw, unstandardized).
  /// @throws std::invalid_argument when the number of columns is not featureCount().
  std::vector<int> predict(const Eigen::MatrixXf& features, Instructions instructions = Instructions::kBest) const;

  /// libsvm's decision values: one row per row of `features`, one column per class pair
  /// (libsvm's pair order), rho subtracted; positive votes for the pair's first class.
  /// @throws std::invalid_argument as predict().
  Eigen::MatrixXf decisionValues(const Eigen::MatrixXf& features,
                                 Instructions instructions = Instructions::kBest) const;

  /// Whether kBest runs the AVX2 path on this CPU.
  static bool vectorKernelAvailable();

 private:
  /// The support vectors feature-major and padded to a multiple of 8 (the padding's
  /// coefficients are 0), their squared norms and the coefficients pair-major: the layout of
  /// the AVX2 path. Made by train() and load().
  void prepareKernel();
  int padded_count_ = 0;
  std::vector<float> support_by_feature_;    // feature x padded support vectors
  std::vector<float> support_norms_;         // padded support vectors
  std::vector<float> coefficients_by_pair_;  // pair x padded support vectors

  std::vector<int> labels_;  // libsvm's class order
  std::map<int, std::string> names_;
  Eigen::VectorXf mean_;
  Eigen::VectorXf scale_;  // divide by
  float gamma_ = 0.0f;
  Eigen::MatrixXf support_vectors_;  // standardized, grouped by class in labels_ order
  std::vector<int> support_counts_;  // per class
  Eigen::MatrixXf coefficients_;     // support vectors x class pairs (libsvm's pair order)
  Eigen::VectorXf rho_;              // per class pair
  SvmTrainingReport report_;
};

}  // namespace costar::perception
