// Stage 3: features (FPFH + colour), the SVM (libsvm), label smoothing.

#include "perception/segmentation.h"

#include <gtest/gtest.h>
#include <svm.h>

#include <random>

#include "perception/svm_classifier.h"
#include "perception/test/synthetic_scene.h"
#include "perception/workspace.h"

namespace costar::perception {
namespace {

/// Three labelled blobs in 5 dimensions.
void blobs(int per_label, std::uint32_t seed, Eigen::MatrixXf& features, std::vector<int>& labels) {
  std::mt19937 random(seed);
  std::normal_distribution<float> noise(0.0f, 0.6f);
  const std::vector<Eigen::VectorXf> centres = {Eigen::VectorXf::Zero(5), Eigen::VectorXf::Constant(5, 2.0f),
                                                (Eigen::VectorXf(5) << 2, -2, 0, 1, -1).finished()};
  features.resize(3 * per_label, 5);
  labels.clear();
  for (int label = 0; label < 3; ++label) {
    for (int i = 0; i < per_label; ++i) {
      const int row = label * per_label + i;
      for (int d = 0; d < 5; ++d) {
        features(row, d) = centres[static_cast<std::size_t>(label)][d] + noise(random);
      }
      labels.push_back(label);
    }
  }
}

const std::map<int, std::string> kNames = {{0, "background"}, {1, "node"}, {2, "link"}};

TEST(Svm, LearnsSeparableLabelsAndReportsCrossValidatedAccuracy) {
  Eigen::MatrixXf features;
  std::vector<int> labels;
  blobs(150, 1, features, labels);
  SvmTrainingReport report;
  const SvmClassifier classifier = SvmClassifier::train(features, labels, kNames, {}, &report);
  EXPECT_EQ(report.folds, 5);
  EXPECT_GT(report.overall_accuracy, 0.97);
  for (const auto& [label, entry] : report.labels) {
    EXPECT_EQ(entry.examples, 150);
    EXPECT_GT(entry.accuracy(), 0.95) << entry.name;
  }
  Eigen::MatrixXf test_features;
  std::vector<int> test_labels;
  blobs(100, 2, test_features, test_labels);
  const std::vector<int> predicted = classifier.predict(test_features);
  int correct = 0;
  for (std::size_t i = 0; i < predicted.size(); ++i) {
    correct += predicted[i] == test_labels[i];
  }
  EXPECT_GT(correct, 290);
  EXPECT_EQ(classifier.labelOf("link"), 2);
  EXPECT_EQ(classifier.labelOf("gear"), -1);
}

TEST(Svm, DensePredictionEqualsLibsvmsOwn) {
  Eigen::MatrixXf features;
  std::vector<int> labels;
  blobs(80, 3, features, labels);
  SvmTrainingOptions options;
  options.folds = 0;
  const SvmClassifier classifier = SvmClassifier::train(features, labels, kNames, options);
  // libsvm itself, on the same standardized data with the same parameters.
  const Eigen::VectorXf mean = features.colwise().mean().transpose();
  const Eigen::VectorXf scale =
      ((features.rowwise() - mean.transpose()).array().square().colwise().sum() / (features.rows() - 1))
          .sqrt()
          .transpose();
  const Eigen::MatrixXf standard =
      (features.rowwise() - mean.transpose()).array().rowwise() / scale.transpose().array();
  std::vector<std::vector<svm_node>> rows(static_cast<std::size_t>(standard.rows()));
  std::vector<svm_node*> pointers;
  std::vector<double> targets;
  for (Eigen::Index r = 0; r < standard.rows(); ++r) {
    for (int d = 0; d < 5; ++d) {
      rows[static_cast<std::size_t>(r)].push_back({d + 1, standard(r, d)});
    }
    rows[static_cast<std::size_t>(r)].push_back({-1, 0});
    pointers.push_back(rows[static_cast<std::size_t>(r)].data());
    targets.push_back(labels[static_cast<std::size_t>(r)]);
  }
  svm_problem problem{static_cast<int>(targets.size()), targets.data(), pointers.data()};
  svm_parameter parameter{};
  parameter.svm_type = C_SVC;
  parameter.kernel_type = RBF;
  parameter.gamma = options.gamma;
  parameter.C = options.cost;
  parameter.cache_size = 100;
  parameter.eps = 1e-3;
  parameter.shrinking = 1;
  svm_model* model = svm_train(&problem, &parameter);
  std::mt19937 random(9);
  std::uniform_real_distribution<float> coordinate(-3.0f, 4.0f);
  Eigen::MatrixXf queries(500, 5);
  for (Eigen::Index r = 0; r < queries.rows(); ++r) {
    for (int d = 0; d < 5; ++d) {
      queries(r, d) = coordinate(random);
    }
  }
  const std::vector<int> ours = classifier.predict(queries);
  int same = 0;
  for (Eigen::Index r = 0; r < queries.rows(); ++r) {
    std::vector<svm_node> x;
    for (int d = 0; d < 5; ++d) {
      x.push_back({d + 1, (queries(r, d) - mean[d]) / scale[d]});
    }
    x.push_back({-1, 0});
    same += static_cast<int>(svm_predict(model, x.data())) == ours[static_cast<std::size_t>(r)];
  }
  svm_free_and_destroy_model(&model);
  EXPECT_GE(same, 498);  // single versus double precision may flip a point on a boundary
}

// The AVX2 path (kBest on a CPU with AVX2 and FMA) computes the same decisions as the portable
// one to float rounding, for row and support-vector counts that are not multiples of its blocks
// (4 rows, 8 support vectors) and every class pair.
TEST(Svm, TheVectorPathGivesThePortableDecisions) {
  if (!SvmClassifier::vectorKernelAvailable()) {
    GTEST_SKIP() << "this CPU has no AVX2 and FMA: kBest is the portable path";
  }
  std::mt19937 random(11);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  constexpr int kDims = 39;  // as the pipeline's features
  Eigen::MatrixXf features(3 * 70, kDims);
  std::vector<int> labels;
  for (int label = 0; label < 3; ++label) {
    for (int i = 0; i < 70; ++i) {
      for (int d = 0; d < kDims; ++d) {
        features(label * 70 + i, d) = noise(random) + (d % 3 == label ? 1.5f : 0.0f);
      }
      labels.push_back(label);
    }
  }
  SvmTrainingOptions options;
  options.folds = 0;
  const SvmClassifier classifier = SvmClassifier::train(features, labels, kNames, options);
  ASSERT_NE(classifier.supportVectorCount() % 8, 0) << "pick data whose support vectors leave a partial block";
  for (const int rows : {1, 3, 4, 203}) {
    Eigen::MatrixXf queries(rows, kDims);
    for (int r = 0; r < rows; ++r) {
      for (int d = 0; d < kDims; ++d) {
        queries(r, d) = 1.3f * noise(random) + (d % 3 == r % 3 ? 1.0f : 0.0f);
      }
    }
    const Eigen::MatrixXf best = classifier.decisionValues(queries, SvmClassifier::Instructions::kBest);
    const Eigen::MatrixXf portable = classifier.decisionValues(queries, SvmClassifier::Instructions::kPortable);
    ASSERT_EQ(best.rows(), rows);
    ASSERT_EQ(best.cols(), 3);
    for (int r = 0; r < rows; ++r) {
      for (int p = 0; p < 3; ++p) {
        EXPECT_NEAR(best(r, p), portable(r, p), 2e-5f * (1.0f + std::abs(portable(r, p)))) << r << ", " << p;
      }
    }
    EXPECT_EQ(classifier.predict(queries, SvmClassifier::Instructions::kBest),
              classifier.predict(queries, SvmClassifier::Instructions::kPortable));
  }
}

TEST(Svm, SavesAndLoads) {
  Eigen::MatrixXf features;
  std::vector<int> labels;
  blobs(60, 4, features, labels);
  const SvmClassifier classifier = SvmClassifier::train(features, labels, kNames);
  const auto file = std::filesystem::temp_directory_path() / "costar_svm_test.json";
  classifier.save(file);
  const SvmClassifier loaded = SvmClassifier::load(file);
  std::filesystem::remove(file);
  EXPECT_EQ(loaded.predict(features), classifier.predict(features));
  EXPECT_EQ(loaded.names(), kNames);
  EXPECT_NEAR(loaded.report().overall_accuracy, classifier.report().overall_accuracy, 1e-9);
  EXPECT_THROW(SvmClassifier::load(file), std::runtime_error);
  EXPECT_THROW(loaded.predict(Eigen::MatrixXf::Zero(2, 3)), std::invalid_argument);
}

TEST(Svm, RefusesBadTrainingData) {
  Eigen::MatrixXf features = Eigen::MatrixXf::Random(10, 3);
  EXPECT_THROW(SvmClassifier::train(features, std::vector<int>(10, 1), kNames), std::invalid_argument);
  EXPECT_THROW(SvmClassifier::train(features, std::vector<int>(9, 1), kNames), std::invalid_argument);
  std::vector<int> labels(10, 0);
  labels[3] = 7;
  EXPECT_THROW(SvmClassifier::train(features, labels, kNames), std::invalid_argument);
}

TEST(Features, ColourFeaturesSeparateHues) {
  const auto red = colorFeatures({200, 20, 20});
  const auto green = colorFeatures({20, 160, 40});
  const auto grey = colorFeatures({128, 128, 128});
  EXPECT_NEAR(grey[3], 0.0f, 1e-6f);  // no saturation
  EXPECT_NEAR(grey[4], 0.0f, 1e-6f);
  EXPECT_GT(red[0], 0.8f);  // chromaticity r
  EXPECT_GT(red[4], 0.7f);  // hue vector towards red
  EXPECT_LT(green[4], 0.0f);
  EXPECT_NEAR(red[2], 200.0f / 255.0f, 1e-6f);
}

TEST(Features, VoxelsGetFpfhHistogramsAndColour) {
  world::ObjectClass block;
  block.boxes = {{Eigen::Vector3d::Zero(), Eigen::Vector3d(0.03, 0.03, 0.03)}};
  const camera::RgbdFrame frame =
      test::renderSynthetic({{&block, world::Pose(Eigen::Translation3d(0.5, 0.0, 0.03)), {30, 60, 200}}});
  WorkspaceCloud workspace = cropWorkspace(frame, {});
  estimateNormals(frame, workspace.cloud);
  const VoxelFeatures voxels = computeFeatures(workspace.cloud);
  ASSERT_GT(voxels.voxels.size(), 30u);
  ASSERT_EQ(voxels.features.cols(), kFeatureCount);
  for (Eigen::Index v = 0; v < voxels.features.rows(); ++v) {
    // Each of FPFH's three sub-histograms sums to 100 %.
    EXPECT_NEAR(voxels.features.row(v).head<kFpfhBins>().sum(), 3.0f, 0.01f);
    EXPECT_NEAR(voxels.features(v, kFpfhBins + 2), 200.0f / 255.0f, 0.01f);
  }
  for (std::size_t i = 0; i < workspace.cloud.size(); ++i) {
    const int v = voxels.voxel_of_point[i];
    EXPECT_LT((voxels.voxels.points[static_cast<std::size_t>(v)] - workspace.cloud.points[i]).norm(), 0.011f);
  }
  // PCL's OpenMP estimator on 2 threads (as the pipeline runs it): the same histograms.
  FeatureOptions two_threads;
  two_threads.threads = 2;
  EXPECT_EQ(computeFeatures(workspace.cloud, two_threads).features, voxels.features);
  Cloud no_normals;
  no_normals.points = {Eigen::Vector3f::Zero()};
  EXPECT_THROW(computeFeatures(no_normals), std::invalid_argument);
}

TEST(Segmentation, SmoothingTakesTheMajorityAround) {
  std::vector<Eigen::Vector3f> points;
  std::vector<int> labels;
  for (int i = 0; i < 20; ++i) {
    points.emplace_back(0.005f * i, 0, 0);
    labels.push_back(i < 10 ? 1 : 2);
  }
  labels[4] = 0;   // a stray label inside the first run
  labels[15] = 1;  // and inside the second
  const std::vector<int> smooth = smoothLabels(points, labels, 0.011);
  EXPECT_EQ(smooth[4], 1);
  EXPECT_EQ(smooth[15], 2);
  EXPECT_EQ(smooth[0], 1);
  EXPECT_EQ(smooth[19], 2);
  EXPECT_EQ(smoothLabels(points, labels, 0.0), labels);
}

TEST(Segmentation, ClassLabelsGrowIntoConnectedBackgroundWithinReach) {
  // One row of 12 pixels, 5 mm apart at 1 m: class 2 at pixels 0-1, background 2-9, then a
  // 5 cm depth jump at pixel 10 (another surface), background 10-11.
  Cloud cloud;
  std::vector<int> labels;
  for (int u = 0; u < 12; ++u) {
    cloud.points.emplace_back(0.005f * u, 0.0f, u < 10 ? 1.0f : 1.05f);
    cloud.pixels.push_back(u);
    labels.push_back(u < 2 ? 2 : 0);
  }
  // Reach 2.8 cm: pixels up to 2.8 cm from the class pixel the growth left from (pixel 1).
  const std::vector<int> grown = growLabels(cloud, 12, 1, labels, 0.008, 0.028);
  for (int u = 0; u <= 6; ++u) {
    EXPECT_EQ(grown[static_cast<std::size_t>(u)], 2) << u;
  }
  EXPECT_EQ(grown[7], 0);
  EXPECT_EQ(grown[9], 0);
  // Long reach: all the connected surface, not across the depth jump.
  const std::vector<int> far = growLabels(cloud, 12, 1, labels, 0.008, 1.0);
  EXPECT_EQ(far[9], 2);
  EXPECT_EQ(far[10], 0);
  EXPECT_EQ(far[11], 0);
  EXPECT_THROW(growLabels(cloud, 12, 1, {1, 2}, 0.008, 0.03), std::invalid_argument);
}

}  // namespace
}  // namespace costar::perception
