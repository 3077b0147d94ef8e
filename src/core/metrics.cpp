#include "evidential_slam/core/metrics.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace evidential_slam {

bool computeAte(const std::vector<StampedPose>& estimate, const std::vector<StampedPose>& truth,
                double max_dt, AteResult* result, std::string* why) {
  auto fail = [why](const std::string& m) {
    if (why != nullptr) *why = m;
    return false;
  };
  if (truth.empty()) return fail("ground truth is empty");
  std::vector<StampedPose> sorted_truth = truth;
  std::sort(sorted_truth.begin(), sorted_truth.end(),
            [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });

  std::vector<Eigen::Vector2d> est_pts, gt_pts;
  for (const StampedPose& e : estimate) {
    auto it = std::lower_bound(sorted_truth.begin(), sorted_truth.end(), e.stamp,
                               [](const StampedPose& a, double t) { return a.stamp < t; });
    const StampedPose* best = nullptr;
    if (it != sorted_truth.end()) best = &*it;
    if (it != sorted_truth.begin()) {
      const StampedPose* prev = &*(it - 1);
      if (best == nullptr || std::abs(prev->stamp - e.stamp) < std::abs(best->stamp - e.stamp)) {
        best = prev;
      }
    }
    if (best == nullptr || std::abs(best->stamp - e.stamp) > max_dt) continue;
    est_pts.push_back(e.pose.translation());
    gt_pts.push_back(best->pose.translation());
  }
  if (est_pts.size() < 2) {
    return fail("fewer than 2 estimated poses have a ground-truth pose within " +
                std::to_string(max_dt) + " s");
  }

  // Dynamic-size matrices: GCC 12 warns falsely inside umeyama for fixed 2-row ones.
  Eigen::MatrixXd src(2, est_pts.size()), dst(2, gt_pts.size());
  for (size_t i = 0; i < est_pts.size(); ++i) {
    src.col(i) = est_pts[i];
    dst.col(i) = gt_pts[i];
  }
  const Eigen::MatrixXd t = Eigen::umeyama(src, dst, /*with_scaling=*/false);
  Eigen::Isometry2d align = Eigen::Isometry2d::Identity();
  align.linear() = t.block<2, 2>(0, 0);
  align.translation() = t.block<2, 1>(0, 2);

  double sum_sq = 0.0, max_err = 0.0;
  for (size_t i = 0; i < est_pts.size(); ++i) {
    const double err = (align * est_pts[i] - gt_pts[i]).norm();
    sum_sq += err * err;
    max_err = std::max(max_err, err);
  }
  result->matched = est_pts.size();
  result->rmse = std::sqrt(sum_sq / static_cast<double>(est_pts.size()));
  result->max_error = max_err;
  result->alignment = Pose2::fromIsometry(align);
  return true;
}

}  // namespace evidential_slam
