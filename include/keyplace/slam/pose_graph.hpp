#pragma once
// An SE(2) pose graph over submap origins (paper Section 6.2.2): odometry edges between
// consecutive submaps and loop edges from place recognition, solved with Ceres. Loop edges carry
// a robust (Cauchy) loss, and loops whose residual stays large after optimisation are switched
// off and the graph is solved again, so that one wrong loop cannot wreck the map.

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

/// A relative-pose constraint: the pose of node `to` in the frame of node `from`.
struct PoseGraphEdge {
  enum class Kind { kOdometry, kLoop };
  Kind kind = Kind::kOdometry;
  int from = 0;
  int to = 0;
  Pose2 T_from_to;
  // Standard deviations of the measurement, in the frame of `from` (m, m, rad); the information
  // is diag(1 / sigma^2).
  double sigma_x_m = 0.1;
  double sigma_y_m = 0.1;
  double sigma_theta_rad = 0.05;
  bool enabled = true;  // false: left out by the caller (see PoseGraph::rejected for the graph's)
};

struct PoseGraphConfig {
  // Outlier loops (switchable constraints decided by a hard test): after a least-squares solve,
  // the loop edge with the largest whitened residual norm (in sigmas) above loop_reject_sigmas is
  // switched off and the graph solved again, up to max_rejection_rounds times per call. Then
  // switched-off loops (also from earlier calls) that fit the solution within the test are
  // switched on again. 0 disables the rejection.
  double loop_reject_sigmas = 5.0;
  int max_rejection_rounds = 10;
  // Finally the graph is solved once more with a Cauchy loss of this scale (in sigmas of the
  // whitened residual) on the loop edges left; odometry edges keep the squared loss. 0 = none.
  // (Not used from the start: with drift of many sigmas, a Cauchy loss barely lets a correct
  // loop pull.)
  double loop_loss_scale = 3.0;
  int max_iterations = 100;  // Ceres iterations per solve
  int threads = 1;           // Ceres threads (1 = deterministic and cheap at this size)
};

/// Throws std::invalid_argument naming the first invalid field.
void Validate(const PoseGraphConfig& config);

struct PoseGraphResult {
  bool converged = false;  // the last Ceres solve reported convergence
  int solves = 0;          // Ceres solves (1 + rejection rounds)
  int iterations = 0;      // Ceres iterations, all solves
  double initial_cost = 0.0;
  double final_cost = 0.0;
  std::vector<int> rejected_loops;  // edge indices switched off in this call
  std::vector<int> restored_loops;  // edge indices switched on again in this call
  double seconds = 0.0;
};

class PoseGraph {
 public:
  /// Adds a node with an initial estimate; returns its index. Node 0 is held fixed (the world).
  int AddNode(const Pose2& initial);
  /// Adds an edge; returns its index. Throws std::invalid_argument for unknown nodes or a
  /// non-positive sigma.
  int AddEdge(const PoseGraphEdge& edge);

  /// Optimises all nodes (node 0 fixed) with the enabled edges, rejecting outlier loops.
  PoseGraphResult Optimize(const PoseGraphConfig& config = {});

  /// The whitened residual norm of an edge at the current estimate (in sigmas).
  double WhitenedResidual(int edge) const;

  std::size_t num_nodes() const { return nodes_.size(); }
  std::size_t num_edges() const { return edges_.size(); }
  Pose2 node(int index) const;
  const std::vector<PoseGraphEdge>& edges() const { return edges_; }
  void SetEdgeEnabled(int edge, bool enabled) { edges_.at(edge).enabled = enabled; }
  /// A loop edge switched off by the outlier test at the last Optimize.
  bool rejected(int edge) const { return rejected_.at(edge); }
  /// Enabled by the caller and not rejected: the edge takes part in the optimisation.
  bool active(int edge) const { return edges_.at(edge).enabled && !rejected_.at(edge); }

 private:
  std::vector<Eigen::Vector3d> nodes_;  // x, y, theta (theta not wrapped while solving)
  std::vector<PoseGraphEdge> edges_;
  std::vector<bool> rejected_;  // per edge
};

}  // namespace keyplace
