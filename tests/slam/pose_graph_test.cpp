#include "keyplace/slam/pose_graph.hpp"

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

PoseGraphEdge Edge(PoseGraphEdge::Kind kind, int from, int to, const Pose2& T, double sigma_m,
                   double sigma_rad) {
  PoseGraphEdge edge;
  edge.kind = kind;
  edge.from = from;
  edge.to = to;
  edge.T_from_to = T;
  edge.sigma_x_m = edge.sigma_y_m = sigma_m;
  edge.sigma_theta_rad = sigma_rad;
  return edge;
}

// A known optimum: translation-only triangle, equal information. Minimising
// (x1-1)^2 + (x2-x1-1)^2 + (x2-2.3)^2 gives x1 = 1.1, x2 = 2.2.
TEST(PoseGraph, LinearTriangleHasTheLeastSquaresOptimum) {
  PoseGraph graph;
  graph.AddNode({0, 0, 0});
  graph.AddNode({0.5, 0.3, 0.1});
  graph.AddNode({3.0, -0.2, -0.1});
  const auto kOdo = PoseGraphEdge::Kind::kOdometry;
  graph.AddEdge(Edge(kOdo, 0, 1, {1, 0, 0}, 0.1, 0.01));
  graph.AddEdge(Edge(kOdo, 1, 2, {1, 0, 0}, 0.1, 0.01));
  graph.AddEdge(Edge(kOdo, 0, 2, {2.3, 0, 0}, 0.1, 0.01));
  const PoseGraphResult result = graph.Optimize();
  EXPECT_TRUE(result.converged);
  EXPECT_NEAR(graph.node(0).x, 0.0, 1e-12);  // node 0 is fixed
  EXPECT_NEAR(graph.node(1).x, 1.1, 1e-6);
  EXPECT_NEAR(graph.node(2).x, 2.2, 1e-6);
  EXPECT_NEAR(graph.node(1).y, 0.0, 1e-6);
  EXPECT_NEAR(graph.node(2).theta, 0.0, 1e-6);
}

TEST(PoseGraph, ConsistentChainIsReproducedAcrossTheAngleWrap) {
  PoseGraph graph;
  const Pose2 step(1.0, 0.2, 2.5);  // turns through +-pi on the way
  Pose2 truth;
  std::vector<Pose2> truths{truth};
  graph.AddNode(truth);
  for (int i = 1; i < 6; ++i) {
    truth = truth * step;
    truths.push_back(truth);
    graph.AddNode({truth.x + 0.3, truth.y - 0.2, truth.theta + 0.2});
    graph.AddEdge(Edge(PoseGraphEdge::Kind::kOdometry, i - 1, i, step, 0.05, 0.01));
  }
  graph.Optimize();
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(graph.node(i).x, truths[i].x, 1e-6) << i;
    EXPECT_NEAR(graph.node(i).y, truths[i].y, 1e-6) << i;
    EXPECT_NEAR(WrapAngle(graph.node(i).theta - truths[i].theta), 0.0, 1e-6) << i;
  }
}

TEST(PoseGraph, RejectsInvalidEdgesAndConfigs) {
  PoseGraph graph;
  graph.AddNode({});
  graph.AddNode({});
  EXPECT_THROW(graph.AddEdge(Edge(PoseGraphEdge::Kind::kLoop, 0, 2, {}, 0.1, 0.1)),
               std::invalid_argument);
  EXPECT_THROW(graph.AddEdge(Edge(PoseGraphEdge::Kind::kLoop, 0, 1, {}, 0.0, 0.1)),
               std::invalid_argument);
  PoseGraphConfig config;
  config.max_iterations = 0;
  EXPECT_THROW(graph.Optimize(config), std::invalid_argument);
}

// A square loop (4 x 10 m sides, 1 m steps) with drifting odometry: heading bias per step.
struct SquareLoop {
  std::vector<Pose2> truth;
  std::vector<Pose2> odometry;  // dead reckoning with a drifting heading
  std::vector<Pose2> steps;     // measured increments
};

SquareLoop MakeSquareLoop() {
  SquareLoop loop;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.01);
  Pose2 truth, odometry;
  loop.truth.push_back(truth);
  loop.odometry.push_back(odometry);
  for (int side = 0; side < 4; ++side) {
    for (int k = 0; k < 10; ++k) {
      const bool corner = k == 9;
      const Pose2 true_step(1.0, 0.0, corner ? M_PI / 2 : 0.0);
      const Pose2 measured(true_step.x + noise(rng), true_step.y + noise(rng),
                           true_step.theta + 0.01 + 0.2 * noise(rng));  // 0.57 deg/step bias
      truth = truth * true_step;
      odometry = odometry * measured;
      loop.truth.push_back(truth);
      loop.odometry.push_back(odometry);
      loop.steps.push_back(measured);
    }
  }
  return loop;
}

PoseGraph SquareGraph(const SquareLoop& loop) {
  PoseGraph graph;
  for (const Pose2& pose : loop.odometry) graph.AddNode(pose);
  for (std::size_t i = 0; i < loop.steps.size(); ++i) {
    graph.AddEdge(Edge(PoseGraphEdge::Kind::kOdometry, static_cast<int>(i), static_cast<int>(i + 1),
                       loop.steps[i], 0.05, 0.01));
  }
  return graph;
}

double MaxPositionError(const PoseGraph& graph, const std::vector<Pose2>& truth) {
  double worst = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    worst = std::max(
        worst, (graph.node(static_cast<int>(i)).translation() - truth[i].translation()).norm());
  }
  return worst;
}

TEST(PoseGraph, LoopEdgeRemovesTheDriftOfASquare) {
  const SquareLoop loop = MakeSquareLoop();
  PoseGraph graph = SquareGraph(loop);
  const double before = MaxPositionError(graph, loop.truth);
  const int last = static_cast<int>(loop.truth.size()) - 1;
  graph.AddEdge(Edge(PoseGraphEdge::Kind::kLoop, 0, last, Between(loop.truth[0], loop.truth[last]),
                     0.05, 0.01));
  const PoseGraphResult result = graph.Optimize();
  const double after = MaxPositionError(graph, loop.truth);
  EXPECT_GT(before, 2.5);
  EXPECT_LT(after, 0.6);
  EXPECT_TRUE(result.rejected_loops.empty());
}

TEST(PoseGraph, PlantedFalseLoopDoesNotPullTheGraph) {
  const SquareLoop loop = MakeSquareLoop();
  PoseGraph graph = SquareGraph(loop);
  const int last = static_cast<int>(loop.truth.size()) - 1;
  graph.AddEdge(Edge(PoseGraphEdge::Kind::kLoop, 0, last, Between(loop.truth[0], loop.truth[last]),
                     0.05, 0.01));
  // Two more correct loops, and a wrong one: node 25 "seen" at node 5's place.
  graph.AddEdge(Edge(PoseGraphEdge::Kind::kLoop, 1, last - 1,
                     Between(loop.truth[1], loop.truth[last - 1]), 0.05, 0.01));
  graph.AddEdge(Edge(PoseGraphEdge::Kind::kLoop, 2, last - 2,
                     Between(loop.truth[2], loop.truth[last - 2]), 0.05, 0.01));
  const int wrong =
      graph.AddEdge(Edge(PoseGraphEdge::Kind::kLoop, 5, 25, Pose2(0.5, 0.2, 0.1), 0.05, 0.01));
  const PoseGraphResult result = graph.Optimize();
  EXPECT_LT(MaxPositionError(graph, loop.truth), 0.6);
  ASSERT_EQ(result.rejected_loops.size(), 1u);
  EXPECT_EQ(result.rejected_loops[0], wrong);
  EXPECT_TRUE(graph.rejected(wrong));
  EXPECT_FALSE(graph.active(wrong));

  // Without the robust loss and the rejection, the same loop wrecks the map.
  PoseGraph naive = SquareGraph(loop);
  naive.AddEdge(Edge(PoseGraphEdge::Kind::kLoop, 0, last, Between(loop.truth[0], loop.truth[last]),
                     0.05, 0.01));
  naive.AddEdge(Edge(PoseGraphEdge::Kind::kLoop, 5, 25, Pose2(0.5, 0.2, 0.1), 0.05, 0.01));
  PoseGraphConfig plain;
  plain.loop_loss_scale = 0.0;
  plain.loop_reject_sigmas = 0.0;
  naive.Optimize(plain);
  EXPECT_GT(MaxPositionError(naive, loop.truth), 1.0);
}

}  // namespace
}  // namespace keyplace
