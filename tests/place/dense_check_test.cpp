// The dense check on synthetic rooms: the true pose scores high and a wrong one low or through a
// wall; in recognition it turns a keypoint match that gamma refuses (an open hall with sparse
// keypoints) into an answer, and refuses one whose walls do not fit (a look-alike).

#include "keyplace/place/dense_check.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {
namespace {

using Segment = std::pair<Eigen::Vector2d, Eigen::Vector2d>;

// A 12 m x 8 m room with an inner wall and a pillar, in the world frame.
std::vector<Segment> Room() {
  const auto s = [](double x0, double y0, double x1, double y1) {
    return Segment{Eigen::Vector2d(x0, y0), Eigen::Vector2d(x1, y1)};
  };
  return {s(0, 0, 12, 0), s(12, 0, 12, 8), s(12, 8, 0, 8), s(0, 8, 0, 0), s(5, 0, 5, 4.5),
          s(8, 5, 9, 5),  s(9, 5, 9, 6),   s(9, 6, 8, 6),  s(8, 6, 8, 5)};
}

std::optional<double> RayHit(const Eigen::Vector2d& origin, const Eigen::Vector2d& direction,
                             const Segment& wall) {
  const Eigen::Vector2d edge = wall.second - wall.first;
  const double denominator = direction.x() * edge.y() - direction.y() * edge.x();
  if (std::abs(denominator) < 1e-12) return std::nullopt;
  const Eigen::Vector2d to_wall = wall.first - origin;
  const double t = (to_wall.x() * edge.y() - to_wall.y() * edge.x()) / denominator;
  const double u = (to_wall.x() * direction.y() - to_wall.y() * direction.x()) / denominator;
  if (t <= 1e-9 || u < 0.0 || u > 1.0) return std::nullopt;
  return t;
}

// 360 beams over 360 degrees from T_world_laser: endpoints in the laser frame.
std::vector<Eigen::Vector2d> CastScan(const std::vector<Segment>& walls,
                                      const Pose2& T_world_laser) {
  std::vector<Eigen::Vector2d> endpoints;
  for (int k = 0; k < 360; ++k) {
    const double bearing = k * M_PI / 180.0;
    const Eigen::Vector2d local(std::cos(bearing), std::sin(bearing));
    const Eigen::Vector2d direction = T_world_laser * local - T_world_laser.translation();
    double nearest = std::numeric_limits<double>::infinity();
    for (const Segment& wall : walls) {
      if (const auto t = RayHit(T_world_laser.translation(), direction, wall)) {
        nearest = std::min(nearest, *t);
      }
    }
    if (std::isfinite(nearest)) endpoints.push_back(nearest * local);
  }
  return endpoints;
}

// The cells (0.1 m) the scans from `poses` end in, in the frame of poses[0] (a submap's).
std::vector<Eigen::Vector2i> OccupiedCells(const std::vector<Segment>& walls,
                                           const std::vector<Pose2>& poses) {
  std::set<std::pair<int, int>> cells;
  for (const Pose2& pose : poses) {
    const Pose2 T_place_laser = Between(poses.front(), pose);
    for (const Eigen::Vector2d& endpoint : CastScan(walls, pose)) {
      const Eigen::Vector2d p = T_place_laser * endpoint;
      cells.emplace(static_cast<int>(std::floor(p.x() / 0.1)),
                    static_cast<int>(std::floor(p.y() / 0.1)));
    }
  }
  std::vector<Eigen::Vector2i> out;
  for (const auto& [i, j] : cells) out.emplace_back(i, j);
  return out;
}

// Query scans taken at `poses` (world), in the frame of poses[0].
std::vector<QueryScanPoints> QueryScans(const std::vector<Segment>& walls,
                                        const std::vector<Pose2>& poses) {
  std::vector<QueryScanPoints> scans;
  for (const Pose2& pose : poses) {
    const Pose2 T_query_laser = Between(poses.front(), pose);
    QueryScanPoints scan;
    scan.origin_m = T_query_laser.translation();
    for (const Eigen::Vector2d& endpoint : CastScan(walls, pose)) {
      scan.endpoints_m.push_back(T_query_laser * endpoint);
    }
    scans.push_back(std::move(scan));
  }
  return scans;
}

const std::vector<Pose2> kMapPoses{{2.0, 2.0, 0.0}, {2.5, 2.5, 0.1}, {3.0, 3.0, 0.2}};
const std::vector<Pose2> kQueryPoses{{2.3, 5.5, -1.0}, {2.8, 5.2, -0.9}, {3.2, 5.0, -0.8}};

TEST(DenseReference, TheTruePoseHitsTheWallsAndWrongOnesDoNot) {
  const DenseReference reference(OccupiedCells(Room(), kMapPoses), 0.1);
  const std::vector<QueryScanPoints> scans = QueryScans(Room(), kQueryPoses);
  const Pose2 T_ref_query = Between(kMapPoses.front(), kQueryPoses.front());

  const DenseScore right = reference.Score(T_ref_query, scans);
  EXPECT_GT(right.endpoints, 500);
  EXPECT_GT(right.hit_fraction, 0.9);
  EXPECT_LT(right.see_through_fraction, 0.05);

  // Half a metre off: most endpoints miss the walls by more than the hit distance.
  const DenseScore shifted = reference.Score(Pose2(0.5, 0.0, 0.0) * T_ref_query, scans);
  EXPECT_LT(shifted.hit_fraction, 0.5);
  // Turned by 90 degrees about the query's first pose: beams cross the room's walls.
  const DenseScore turned = reference.Score(T_ref_query * Pose2(0.0, 0.0, M_PI / 2), scans);
  EXPECT_LT(turned.hit_fraction, 0.5);
  EXPECT_GT(turned.see_through_fraction, 0.2);
}

TEST(DenseReference, EndpointsOutsideTheReferenceCountForNothing) {
  const DenseReference reference(OccupiedCells(Room(), kMapPoses), 0.1);
  const std::vector<QueryScanPoints> scans = QueryScans(Room(), kQueryPoses);
  const DenseScore far = reference.Score(Pose2(100.0, 100.0, 0.0), scans);
  EXPECT_EQ(far.endpoints, 0);
  EXPECT_EQ(far.rays, 0);
  EXPECT_EQ(far.hit_fraction, 0.0);
  // A beam a million kilometres long is walked only where it crosses the reference: it passes
  // through the room's wall, and the walk is bounded by the room, not by the beam.
  QueryScanPoints far_beam;
  far_beam.origin_m = Eigen::Vector2d(1.0, 1.0);
  far_beam.endpoints_m.emplace_back(1.0e9, 1.0);
  const DenseScore through = reference.Score(Pose2(), {far_beam});
  EXPECT_EQ(through.rays, 1);
  EXPECT_EQ(through.see_through_fraction, 1.0);
  EXPECT_TRUE(DenseReference({}, 0.1).empty());
  EXPECT_THROW(DenseReference({}, 0.0), std::invalid_argument);
}

// The see-through walk as documented, sample by sample over the whole beam (no clipping to the
// occupied box, no skipping of empty blocks): a beam crossed the reference when one of its samples
// every half cell, short of kDenseSeeThroughMarginM before its endpoint, falls in the occupied
// cells' box, and saw through when such a sample is occupied and the point kDenseWallCrossingM
// further on is more than kDenseHitDistanceM (two cells) from every occupied cell.
struct NaiveRays {
  int rays = 0;
  int seen_through = 0;
};
NaiveRays NaiveWalk(const std::vector<Eigen::Vector2i>& cells, const Pose2& T_ref_query,
                    const std::vector<QueryScanPoints>& scans) {
  constexpr double kCell = 0.1;
  std::set<std::pair<int, int>> occupied;
  Eigen::Vector2i lo = cells.front();
  Eigen::Vector2i hi = cells.front();
  for (const Eigen::Vector2i& c : cells) {
    occupied.emplace(c.x(), c.y());
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const auto cell_of = [](const Eigen::Vector2d& p) {
    return std::pair<double, double>(std::floor(p.x() / kCell), std::floor(p.y() / kCell));
  };
  const auto near_occupied = [&](const Eigen::Vector2d& p) {
    const auto [i, j] = cell_of(p);
    for (int di = -2; di <= 2; ++di) {
      for (int dj = -2; dj <= 2; ++dj) {
        if (di * di + dj * dj <= 4 &&
            occupied.count({static_cast<int>(i) + di, static_cast<int>(j) + dj}) > 0) {
          return true;
        }
      }
    }
    return false;
  };
  NaiveRays out;
  for (const QueryScanPoints& scan : scans) {
    const Eigen::Vector2d origin = T_ref_query * scan.origin_m;
    for (const Eigen::Vector2d& endpoint_query : scan.endpoints_m) {
      const Eigen::Vector2d endpoint = T_ref_query * endpoint_query;
      const double length = (endpoint - origin).norm();
      const double free_length = length - kDenseSeeThroughMarginM;
      if (!(free_length > 0.0)) continue;
      const Eigen::Vector2d direction = (endpoint - origin) / length;
      bool crossed = false;
      bool through = false;
      for (std::int64_t k = 0; !through; ++k) {
        const double s = static_cast<double>(k) * 0.5 * kCell;
        if (s >= free_length) break;
        const auto [i, j] = cell_of(origin + s * direction);
        if (i < lo.x() || i > hi.x() || j < lo.y() || j > hi.y()) continue;
        crossed = true;
        if (occupied.count({static_cast<int>(i), static_cast<int>(j)}) == 0) continue;
        const double beyond = s + kDenseWallCrossingM;
        through = beyond < free_length && !near_occupied(origin + beyond * direction);
      }
      out.rays += crossed ? 1 : 0;
      out.seen_through += through ? 1 : 0;
    }
  }
  return out;
}

// Score walks only the box's stretch of each beam and jumps over blocks without walls, and with a
// veto it stops once the veto is certain: the counts must be the plain walk's, and a pose is
// vetoed exactly when the full score meets the veto.
TEST(DenseReference, ShortcutsGiveThePlainWalksScore) {
  const std::vector<Eigen::Vector2i> cells = OccupiedCells(Room(), kMapPoses);
  const DenseReference reference(cells, 0.1);
  const std::vector<QueryScanPoints> scans = QueryScans(Room(), kQueryPoses);
  const Pose2 T_true = Between(kMapPoses.front(), kQueryPoses.front());
  DenseVeto veto;
  veto.min_endpoints = 50;
  veto.min_hit_fraction = 0.5;
  veto.max_see_through = 0.3;
  std::mt19937 rng(5);
  std::normal_distribution<double> metres(0.0, 0.6);
  std::normal_distribution<double> radians(0.0, 0.5);
  int vetoed = 0;
  int through_some_wall = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Pose2 T_ref_query =
        trial == 0 ? T_true : Pose2(metres(rng), metres(rng), radians(rng)) * T_true;
    const DenseScore score = reference.Score(T_ref_query, scans);
    const NaiveRays naive = NaiveWalk(cells, T_ref_query, scans);
    ASSERT_EQ(score.rays, naive.rays) << "trial " << trial;
    ASSERT_EQ(score.see_through_fraction,
              naive.rays > 0 ? static_cast<double>(naive.seen_through) / naive.rays : 0.0)
        << "trial " << trial;
    through_some_wall += naive.seen_through > 0 ? 1 : 0;

    const DenseScore with_veto = reference.Score(T_ref_query, scans, veto);
    const bool should_veto = score.endpoints >= veto.min_endpoints &&
                             (score.hit_fraction < veto.min_hit_fraction ||
                              score.see_through_fraction > veto.max_see_through);
    ASSERT_EQ(with_veto.vetoed, should_veto) << "trial " << trial;
    EXPECT_FALSE(score.vetoed);
    if (should_veto) {
      ++vetoed;
      continue;
    }
    EXPECT_EQ(with_veto.endpoints, score.endpoints);
    EXPECT_EQ(with_veto.hit_fraction, score.hit_fraction);
    EXPECT_EQ(with_veto.rays, score.rays);
    EXPECT_EQ(with_veto.see_through_fraction, score.see_through_fraction);
  }
  // Both kinds of pose were met, and walls were seen through.
  EXPECT_GT(vetoed, 10);
  EXPECT_LT(vetoed, 59);
  EXPECT_GT(through_some_wall, 10);
}

// A pose HitsReaching gives up on falls short of the bar, one it scores gets Hits' result (which
// is Score's, computed apart, on every endpoint), and when every endpoint lies in the reference's
// area (so none can leave the count) it gives up on exactly those below the bar.
TEST(DenseReference, HitsReachingGivesUpOnlyOnPosesBelowTheBar) {
  const std::vector<Eigen::Vector2i> cells = OccupiedCells(Room(), kMapPoses);
  // The same walls with the area grown far beyond the room by two lone cells: no endpoint leaves.
  std::vector<Eigen::Vector2i> grown = cells;
  grown.emplace_back(-500, -500);
  grown.emplace_back(500, 500);
  const std::vector<QueryScanPoints> scans = QueryScans(Room(), kQueryPoses);
  const Pose2 T_true = Between(kMapPoses.front(), kQueryPoses.front());
  std::mt19937 rng(3);
  std::normal_distribution<double> metres(0.0, 0.15);
  std::normal_distribution<double> radians(0.0, 0.05);
  int given_up = 0;
  int reached = 0;
  int all_inside = 0;
  int reached_with_some_outside = 0;
  for (int trial = 0; trial < 240; ++trial) {
    const bool all_in_area = trial % 3 == 0;
    const DenseReference reference(all_in_area ? grown : cells, 0.1);
    const Pose2 T_ref_query = Pose2(metres(rng), metres(rng), radians(rng)) * T_true;
    const std::size_t stride = 1 + (trial / 4) % 2;
    const double bar = 0.3 + 0.2 * (trial % 4);
    SCOPED_TRACE(trial);
    const DenseScore hits = reference.Hits(T_ref_query, scans, stride);
    if (stride == 1) {
      const DenseScore score = reference.Score(T_ref_query, scans);
      ASSERT_EQ(hits.endpoints, score.endpoints);
      ASSERT_EQ(hits.hit_fraction, score.hit_fraction);
    }
    const std::optional<DenseScore> reaching =
        reference.HitsReaching(T_ref_query, scans, stride, bar);
    if (!reaching) {
      ++given_up;
      EXPECT_LT(hits.hit_fraction, bar);
    } else {
      EXPECT_EQ(reaching->endpoints, hits.endpoints);
      EXPECT_EQ(reaching->hit_fraction, hits.hit_fraction);
      if (hits.hit_fraction >= bar) ++reached;
    }
    std::size_t probed = 0;  // every stride-th endpoint of each scan
    for (const QueryScanPoints& scan : scans) {
      probed += (scan.endpoints_m.size() + stride - 1) / stride;
    }
    if (static_cast<std::size_t>(hits.endpoints) == probed) {
      ++all_inside;
      EXPECT_EQ(reaching.has_value(), hits.hit_fraction >= bar);
    } else if (reaching && hits.hit_fraction >= bar) {
      ++reached_with_some_outside;
    }
  }
  EXPECT_GT(given_up, 20);
  EXPECT_GT(reached, 20);
  EXPECT_GT(all_inside, 20);
  EXPECT_GT(reached_with_some_outside, 5);
}

// Single occupied cells scattered over a hall, many of them just past the border of a skipped
// block, and beams at every angle: a beam that jumped one sample too far would miss a cell the
// plain walk enters (and, the cells being alone, sees through).
TEST(DenseReference, ShortcutsMissNoSingleCell) {
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> cell(0, 159);
  std::uniform_int_distribution<int> offset(-1, 1);
  std::vector<Eigen::Vector2i> cells;
  for (int k = 0; k < 150; ++k) cells.emplace_back(cell(rng), cell(rng));
  // Around the borders of the 8-cell blocks (the raster starts 2 cells before the box).
  for (int k = 0; k < 150; ++k) {
    cells.emplace_back(8 * (cell(rng) / 8) + 6 + offset(rng), cell(rng));
    cells.emplace_back(cell(rng), 8 * (cell(rng) / 8) + 6 + offset(rng));
  }
  const DenseReference reference(cells, 0.1);
  std::uniform_real_distribution<double> metres(-2.0, 18.0);
  std::vector<QueryScanPoints> scans(20);
  for (QueryScanPoints& scan : scans) {
    scan.origin_m = Eigen::Vector2d(metres(rng), metres(rng));
    for (int b = 0; b < 100; ++b) scan.endpoints_m.emplace_back(metres(rng), metres(rng));
  }
  const DenseScore score = reference.Score(Pose2(), scans);
  const NaiveRays naive = NaiveWalk(cells, Pose2(), scans);
  EXPECT_EQ(score.rays, naive.rays);
  ASSERT_GT(naive.rays, 1500);
  EXPECT_GT(naive.seen_through, 300);
  EXPECT_EQ(score.see_through_fraction, static_cast<double>(naive.seen_through) / naive.rays);
}

// Keypoints on the room's walls with distinct descriptors, in the place frame (kMapPoses[0]).
BetaGridDescriptor Descriptor(int code) {
  BetaGridDescriptor d{};
  d[static_cast<std::size_t>(code % kBetaGridBins)] = 1.0f;
  return d;
}

// An open hall as the keypoints see it: a place and a query that share 12 keypoints (enough
// consensus) while the query's own stable keypoints are elsewhere, so gamma is 0.
std::pair<Place, PlaceQuery> SparseMatch(const std::vector<Segment>& query_walls) {
  Place place;
  place.id = 0;
  place.T_world_place = kMapPoses.front();
  place.scan_indices = {0, 1, 2};
  place.occupancy_cells = OccupiedCells(Room(), kMapPoses);
  place.occupancy_cell_m = 0.1;
  PlaceQuery query;
  const Pose2 T_query_place = Between(kQueryPoses.front(), kMapPoses.front());
  for (int k = 0; k < 12; ++k) {
    const Eigen::Vector2d world(0.5 + 0.9 * k, k % 2 == 0 ? 0.0 : 8.0);
    place.positions.push_back(kMapPoses.front().inverse() * world);
    place.descriptors.push_back(Descriptor(k));
    query.all_positions.push_back(T_query_place * place.positions.back());
    query.all_descriptors.push_back(Descriptor(k));
  }
  for (int k = 0; k < 4; ++k) {  // stable query keypoints that double-match nothing
    query.positions.emplace_back(20.0 + k, 20.0);
    query.descriptors.push_back(Descriptor(40 + k));
  }
  query.scans = QueryScans(query_walls, kQueryPoses);
  return {place, query};
}

TEST(DenseCheck, BeamsThatConfirmThePosePassInPlaceOfGamma) {
  const auto [place, query] = SparseMatch(Room());
  PlaceRecognitionConfig gamma_only;
  gamma_only.dense_min_hit_fraction = 0.0;
  const PlaceMatch refused = PlaceRecognizer({place}, gamma_only).Recognize(query);
  EXPECT_FALSE(refused.verified);  // gamma 0 < 0.15

  const PlaceMatch answered = PlaceRecognizer({place}, PlaceRecognitionConfig{}).Recognize(query);
  ASSERT_TRUE(answered.found);
  EXPECT_TRUE(answered.dense_checked);
  EXPECT_TRUE(answered.verified_candidates.front().dense_sure);
  EXPECT_GT(answered.dense.hit_fraction, 0.9);
  EXPECT_EQ(answered.gamma, 0.0);
  const Pose2& expected = kQueryPoses.front();  // T_first_evaluated is the identity
  EXPECT_NEAR(answered.estimated_pose.x, expected.x, 1e-6);
  EXPECT_NEAR(answered.estimated_pose.y, expected.y, 1e-6);

  // Without the query's beams the check cannot apply and gamma decides again.
  PlaceQuery without_scans = query;
  without_scans.scans.clear();
  EXPECT_FALSE(
      PlaceRecognizer({place}, PlaceRecognitionConfig{}).Recognize(without_scans).verified);
}

TEST(DenseCheck, RefusesALookAlikeWhoseWallsDoNotFit) {
  // The same keypoints, but the query was taken in a room without the inner wall, with its
  // pillar elsewhere and 1 m shorter: the keypoints agree, the beams do not.
  const std::vector<Segment> other{{{0, 0}, {12, 0}}, {{12, 0}, {12, 7}}, {{12, 7}, {0, 7}},
                                   {{0, 7}, {0, 0}},  {{3, 2}, {4, 2}},   {{4, 2}, {4, 3}}};
  const auto [place, query] = SparseMatch(other);
  PlaceRecognitionConfig keypoints_accept;
  keypoints_accept.dense_min_hit_fraction = 0.0;
  keypoints_accept.min_gamma_all_scans = 0.0;
  EXPECT_TRUE(PlaceRecognizer({place}, keypoints_accept).Recognize(query).found);

  // The veto: gamma passes (its threshold is 0), the beams refuse.
  PlaceRecognitionConfig dense = keypoints_accept;
  dense.dense_min_hit_fraction = PlaceRecognitionConfig{}.dense_min_hit_fraction;
  const PlaceMatch match = PlaceRecognizer({place}, dense).Recognize(query);
  EXPECT_FALSE(match.verified);
}

// Beams that support the pose but not beyond doubt, and no gamma: no answer, but a weak one.
TEST(DenseCheck, APoseTheBeamsSupportWithoutGammaIsAWeakAnswer) {
  const auto [place, query] = SparseMatch(Room());
  PlaceRecognitionConfig never_sure;
  never_sure.dense_sure_hit_fraction = 1.0;
  never_sure.dense_sure_see_through = 0.0;
  const PlaceMatch match = PlaceRecognizer({place}, never_sure).Recognize(query);
  EXPECT_FALSE(match.verified);  // gamma 0 < 0.15, and the beams are not "sure"
  ASSERT_TRUE(match.weak.has_value());
  EXPECT_TRUE(match.weak->dense_supported);
  EXPECT_FALSE(match.weak->verified);
  EXPECT_EQ(match.weak->consensus, 12);
  EXPECT_EQ(match.weak_confidence, 0.0);  // gamma 0
  const Pose2& expected = kQueryPoses.front();
  EXPECT_NEAR(match.weak->estimated_pose.x, expected.x, 1e-6);
  EXPECT_NEAR(match.weak->estimated_pose.y, expected.y, 1e-6);

  // Without beams nothing supports the pose: no weak answer either.
  PlaceQuery without_scans = query;
  without_scans.scans.clear();
  EXPECT_FALSE(PlaceRecognizer({place}, never_sure).Recognize(without_scans).weak.has_value());

  // The same place twice, 5 m apart in the map: the beams fit both, which is no answer.
  Place twin = place;
  twin.id = 7;
  twin.T_world_place = Pose2(5.0, 0.0, 0.0) * place.T_world_place;
  EXPECT_FALSE(PlaceRecognizer({place, twin}, never_sure).Recognize(query).weak.has_value());
}

TEST(DenseCheck, AVetoedPoseIsNoWeakAnswer) {
  const std::vector<Segment> other{{{0, 0}, {12, 0}}, {{12, 0}, {12, 7}}, {{12, 7}, {0, 7}},
                                   {{0, 7}, {0, 0}},  {{3, 2}, {4, 2}},   {{4, 2}, {4, 3}}};
  const auto [place, query] = SparseMatch(other);
  const PlaceMatch match = PlaceRecognizer({place}, PlaceRecognitionConfig{}).Recognize(query);
  EXPECT_FALSE(match.verified);
  EXPECT_FALSE(match.weak.has_value());
}

}  // namespace
}  // namespace keyplace
