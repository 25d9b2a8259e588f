#include "keyplace/slam/pose_graph.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include <ceres/ceres.h>

namespace keyplace {
namespace {

// Residual of an SE(2) relative-pose measurement, whitened by diag(1 / sigma):
// e = [R_from^T (t_to - t_from) - t_meas; wrap(theta_to - theta_from - theta_meas)].
struct RelativePoseResidual {
  RelativePoseResidual(const Pose2& measured, double sx, double sy, double st)
      : x(measured.x),
        y(measured.y),
        theta(measured.theta),
        wx(1.0 / sx),
        wy(1.0 / sy),
        wt(1.0 / st) {}

  template <typename T>
  bool operator()(const T* const from, const T* const to, T* residual) const {
    using std::atan2;
    using std::cos;
    using std::sin;
    const T dx = to[0] - from[0];
    const T dy = to[1] - from[1];
    const T c = cos(from[2]);
    const T s = sin(from[2]);
    const T local_x = c * dx + s * dy;
    const T local_y = -s * dx + c * dy;
    const T dtheta = to[2] - from[2] - T(theta);
    residual[0] = T(wx) * (local_x - T(x));
    residual[1] = T(wy) * (local_y - T(y));
    residual[2] = T(wt) * atan2(sin(dtheta), cos(dtheta));
    return true;
  }

  double x, y, theta, wx, wy, wt;
};

Eigen::Vector3d Residual(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                         const PoseGraphEdge& edge) {
  const RelativePoseResidual functor(edge.T_from_to, edge.sigma_x_m, edge.sigma_y_m,
                                     edge.sigma_theta_rad);
  Eigen::Vector3d residual;
  functor(from.data(), to.data(), residual.data());
  return residual;
}

}  // namespace

void Validate(const PoseGraphConfig& config) {
  auto fail = [](const std::string& field, const std::string& why) {
    throw std::invalid_argument("PoseGraphConfig." + field + ": " + why);
  };
  if (!(config.loop_loss_scale >= 0.0)) fail("loop_loss_scale", "must be >= 0");
  if (!(config.loop_reject_sigmas >= 0.0)) fail("loop_reject_sigmas", "must be >= 0");
  if (config.max_rejection_rounds < 0) fail("max_rejection_rounds", "must be >= 0");
  if (config.max_iterations < 1) fail("max_iterations", "must be >= 1");
  if (config.threads < 1) fail("threads", "must be >= 1");
}

int PoseGraph::AddNode(const Pose2& initial) {
  nodes_.emplace_back(initial.x, initial.y, initial.theta);
  return static_cast<int>(nodes_.size()) - 1;
}

int PoseGraph::AddEdge(const PoseGraphEdge& edge) {
  const int n = static_cast<int>(nodes_.size());
  if (edge.from < 0 || edge.from >= n || edge.to < 0 || edge.to >= n || edge.from == edge.to) {
    throw std::invalid_argument("PoseGraph::AddEdge: nodes " + std::to_string(edge.from) + " -> " +
                                std::to_string(edge.to) + " invalid (" + std::to_string(n) +
                                " nodes)");
  }
  if (!(edge.sigma_x_m > 0.0) || !(edge.sigma_y_m > 0.0) || !(edge.sigma_theta_rad > 0.0)) {
    throw std::invalid_argument("PoseGraph::AddEdge: sigmas must be > 0");
  }
  edges_.push_back(edge);
  rejected_.push_back(false);
  return static_cast<int>(edges_.size()) - 1;
}

Pose2 PoseGraph::node(int index) const {
  const Eigen::Vector3d& v = nodes_.at(index);
  return {v.x(), v.y(), v.z()};
}

double PoseGraph::WhitenedResidual(int edge) const {
  const PoseGraphEdge& e = edges_.at(edge);
  return Residual(nodes_[e.from], nodes_[e.to], e).norm();
}

PoseGraphResult PoseGraph::Optimize(const PoseGraphConfig& config) {
  Validate(config);
  const auto start = std::chrono::steady_clock::now();
  PoseGraphResult result;
  if (nodes_.size() < 2) {
    result.converged = true;
    return result;
  }
  auto solve = [&](bool robust) {
    ceres::Problem::Options problem_options;
    problem_options.loss_function_ownership = ceres::TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    for (Eigen::Vector3d& node : nodes_) problem.AddParameterBlock(node.data(), 3);
    problem.SetParameterBlockConstant(nodes_[0].data());
    for (std::size_t i = 0; i < edges_.size(); ++i) {
      const PoseGraphEdge& edge = edges_[i];
      if (!active(static_cast<int>(i))) continue;
      auto* cost =
          new ceres::AutoDiffCostFunction<RelativePoseResidual, 3, 3, 3>(new RelativePoseResidual(
              edge.T_from_to, edge.sigma_x_m, edge.sigma_y_m, edge.sigma_theta_rad));
      ceres::LossFunction* loss = nullptr;
      if (robust && edge.kind == PoseGraphEdge::Kind::kLoop) {
        loss = new ceres::CauchyLoss(config.loop_loss_scale);
      }
      problem.AddResidualBlock(cost, loss, nodes_[edge.from].data(), nodes_[edge.to].data());
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    options.max_num_iterations = config.max_iterations;
    options.num_threads = config.threads;
    options.function_tolerance = 1e-10;
    options.gradient_tolerance = 1e-12;
    options.parameter_tolerance = 1e-10;
    options.logging_type = ceres::SILENT;
    options.minimizer_progress_to_stdout = false;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    if (result.solves == 0) result.initial_cost = summary.initial_cost;
    ++result.solves;
    result.iterations += static_cast<int>(summary.iterations.size());
    result.final_cost = summary.final_cost;
    result.converged = summary.termination_type == ceres::CONVERGENCE;
    for (Eigen::Vector3d& node : nodes_) node.z() = WrapAngle(node.z());
  };
  // The loop (active or not) with the largest whitened residual above the test, or -1.
  auto worst_loop = [&](bool among_active) {
    int worst = -1;
    double worst_residual = config.loop_reject_sigmas;
    for (std::size_t i = 0; i < edges_.size(); ++i) {
      const PoseGraphEdge& edge = edges_[i];
      if (!edge.enabled || edge.kind != PoseGraphEdge::Kind::kLoop) continue;
      if (among_active != !rejected_[i]) continue;
      const double r = WhitenedResidual(static_cast<int>(i));
      if (among_active ? r > worst_residual : r <= config.loop_reject_sigmas) {
        worst_residual = r;
        worst = static_cast<int>(i);
        if (!among_active) break;
      }
    }
    return worst;
  };

  // 1. Least squares, switching off the loop the solution supports least (beyond the test), one
  //    at a time, since a wrong loop also strains the correct ones.
  solve(false);
  if (config.loop_reject_sigmas > 0.0) {
    for (int round = 0; round < config.max_rejection_rounds; ++round) {
      const int worst = worst_loop(true);
      if (worst < 0) break;
      rejected_[worst] = true;
      result.rejected_loops.push_back(worst);
      solve(false);
    }
    // 2. Loops switched off earlier (also in earlier calls) that fit the solution now are
    //    switched on again.
    bool restored = false;
    for (int guard = 0; guard < static_cast<int>(edges_.size()); ++guard) {
      const int fits = worst_loop(false);
      if (fits < 0) break;
      rejected_[fits] = false;
      result.restored_loops.push_back(fits);
      restored = true;
    }
    if (restored) solve(false);
  }
  // 3. A final solve with the robust loss on the loops that remain.
  if (config.loop_loss_scale > 0.0) solve(true);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace keyplace
