#include <cmath>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/localization/relocalizer.hpp"

namespace keyplace {
namespace {

// An accepted answer saying the odometry frame sits at T_world_odom in the map.
LocalizationResult Answer(const Pose2& T_world_odom, double confidence = 0.5) {
  LocalizationResult answer;
  answer.found = true;
  answer.confidence = confidence;
  answer.T_world_odom = T_world_odom;
  return answer;
}

// An answer not accepted that names a weak pose (LocalizationResult::weak_T_world_odom).
LocalizationResult WeakAnswer(const Pose2& T_world_odom, long long query_id = -1,
                              double confidence = 0.05) {
  LocalizationResult answer;
  answer.weak_T_world_odom = T_world_odom;
  answer.match.weak_confidence = confidence;
  answer.query_id = query_id;
  return answer;
}

// The robot drives along +x in its odometry frame, 0.25 m per scan.
Pose2 Odometry(int scan) { return {0.25 * scan, 0.0, 0.0}; }

const Pose2 kTrue(10.0, 5.0, 0.3);  // the true map <- odometry transform
const Pose2 kWrong(-20.0, 3.0, 2.0);

TEST(FixFilter, OneAnswerIsNotAFixTwoThatAgreeAre) {
  FixFilter filter;
  RelocalizationUpdate update = filter.Update(Answer(kTrue), Odometry(0));
  EXPECT_EQ(update.status, FixStatus::kSearching);
  EXPECT_FALSE(update.new_fix);
  for (int scan = 1; scan < 6; ++scan) {
    EXPECT_EQ(filter.Update(std::nullopt, Odometry(scan)).status, FixStatus::kSearching);
  }
  // The second answer is a little off (0.3 m): they agree through odometry.
  update = filter.Update(Answer(kTrue * Pose2(0.3, 0.0, 0.02)), Odometry(6));
  ASSERT_EQ(update.status, FixStatus::kFixed);
  EXPECT_TRUE(update.new_fix);
  EXPECT_NEAR(update.confidence, 0.75, 1e-12);  // 1 - 0.5 * 0.5
  // The fix follows odometry from the newest answer.
  update = filter.Update(std::nullopt, Odometry(8));
  const Pose2 expected = kTrue * Pose2(0.3, 0.0, 0.02) * Odometry(8);
  EXPECT_NEAR(update.T_world_robot.x, expected.x, 1e-9);
  EXPECT_NEAR(update.T_world_robot.y, expected.y, 1e-9);
  EXPECT_FALSE(update.new_fix);
}

// Answers of searches of the whole map (LocalizationResult::window_first_scan, window_last_scan)
// confirm each other only from windows sharing at most one scan: overlapping windows hold the
// same beams. A keypoint answer confirms either.
TEST(FixFilter, SearchesOverTheSameScansDoNotConfirmEachOther) {
  const auto searched = [](long long first_scan, long long last_scan) {
    LocalizationResult answer = Answer(kTrue);
    answer.window_first_scan = first_scan;
    answer.window_last_scan = last_scan;
    return answer;
  };
  FixFilter filter;
  filter.Update(searched(0, 20), Odometry(20));
  EXPECT_EQ(filter.Update(searched(4, 24), Odometry(24)).status, FixStatus::kSearching);
  EXPECT_EQ(filter.Update(searched(19, 39), Odometry(39)).status, FixStatus::kSearching);
  // Sharing the boundary scan only with the first: two looks.
  const RelocalizationUpdate update = filter.Update(searched(20, 40), Odometry(40));
  EXPECT_EQ(update.status, FixStatus::kFixed);
  EXPECT_TRUE(update.new_fix);

  filter.Reset();
  filter.Update(searched(0, 20), Odometry(20));
  EXPECT_EQ(filter.Update(Answer(kTrue), Odometry(21)).status, FixStatus::kFixed);
}

// What the Relocalizer tells its localizer to search near (LocalizerConfig::search_near_m): every
// answer held while searching, then the fix and the answers challenging it.
TEST(FixFilter, BeliefsAreTheAnswersHeldAndTheFix) {
  FixFilter filter;
  EXPECT_TRUE(filter.Beliefs().empty());
  filter.Update(Answer(kWrong), Odometry(0));
  filter.Update(Answer(kTrue), Odometry(8));
  std::vector<Pose2> beliefs = filter.Beliefs();
  ASSERT_EQ(beliefs.size(), 2u);
  EXPECT_EQ(beliefs[0].x, kWrong.x);
  EXPECT_EQ(beliefs[1].x, kTrue.x);
  ASSERT_EQ(filter.Update(Answer(kTrue), Odometry(16)).status, FixStatus::kFixed);
  beliefs = filter.Beliefs();
  ASSERT_FALSE(beliefs.empty());
  EXPECT_NEAR(beliefs.front().x, kTrue.x, 0.01);  // the fix comes first
  EXPECT_NEAR(beliefs.front().y, kTrue.y, 0.01);
  filter.Reset();
  EXPECT_TRUE(filter.Beliefs().empty());
  // An answer older than the window (20 m of odometry) is forgotten before the next one comes.
  filter.Update(Answer(kTrue), Odometry(0));
  filter.Update(std::nullopt, Odometry(80));  // 20 m on: still within
  EXPECT_EQ(filter.Beliefs().size(), 1u);
  filter.Update(std::nullopt, Odometry(81));
  EXPECT_TRUE(filter.Beliefs().empty());
}

// Answers of one growing query (LocalizerConfig::query_every_m) share scans: a wrong pose they
// agree on is one mistake seen twice, so only an answer of another query confirms it, while
// searching and when challenging a fix.
LocalizationResult AnswerOfQuery(const Pose2& T_world_odom, long long query_id,
                                 double confidence = 0.5) {
  LocalizationResult answer = Answer(T_world_odom, confidence);
  answer.query_id = query_id;
  return answer;
}

TEST(FixFilter, AnswersOfOneQueryDoNotConfirmEachOther) {
  FixFilter filter;
  filter.Update(AnswerOfQuery(kTrue, 7), Odometry(0));
  EXPECT_EQ(filter.Update(AnswerOfQuery(kTrue, 7), Odometry(4)).status, FixStatus::kSearching);
  EXPECT_EQ(filter.Update(AnswerOfQuery(kTrue, 7), Odometry(8)).status, FixStatus::kSearching);
  const RelocalizationUpdate update = filter.Update(AnswerOfQuery(kTrue, 8), Odometry(12));
  EXPECT_EQ(update.status, FixStatus::kFixed);
  EXPECT_TRUE(update.new_fix);

  // Two challengers of one query do not overturn the fix; a third of another query does.
  EXPECT_TRUE(filter.Update(AnswerOfQuery(kWrong, 9), Odometry(13)).contradicted);
  EXPECT_EQ(filter.Update(AnswerOfQuery(kWrong, 9), Odometry(14)).status, FixStatus::kFixed);
  EXPECT_FALSE(filter.Update(AnswerOfQuery(kWrong, 9), Odometry(15)).new_fix);
  const RelocalizationUpdate overturned = filter.Update(AnswerOfQuery(kWrong, 10), Odometry(16));
  EXPECT_TRUE(overturned.lost);
  EXPECT_TRUE(overturned.new_fix);
  EXPECT_NEAR(overturned.T_world_odom.x, kWrong.x, 1e-9);
}

TEST(FixFilter, AnswersThatDisagreeGiveNoFix) {
  FixFilter filter;
  filter.Update(Answer(kTrue), Odometry(0));
  const RelocalizationUpdate update = filter.Update(Answer(kWrong), Odometry(5));
  EXPECT_EQ(update.status, FixStatus::kSearching);
  // 1.5 m apart is beyond agree_m + agree_per_m * 1.25 m.
  EXPECT_EQ(filter.Update(Answer(kTrue * Pose2(0.0, 1.5, 0.0)), Odometry(10)).status,
            FixStatus::kSearching);
  // But the third answer agreeing with the first makes the fix.
  EXPECT_EQ(filter.Update(Answer(kTrue * Pose2(0.1, 0.0, 0.0)), Odometry(15)).status,
            FixStatus::kFixed);
}

TEST(FixFilter, AnswersNotAcceptedAreIgnored) {
  FixFilter filter;
  LocalizationResult ambiguous = Answer(kTrue);
  ambiguous.found = false;
  ambiguous.ambiguous = true;
  filter.Update(ambiguous, Odometry(0));
  EXPECT_EQ(filter.Update(Answer(kTrue), Odometry(5)).status, FixStatus::kSearching);
}

TEST(FixFilter, OdometryDriftWidensAgreementWithDistance) {
  FixPolicy policy;
  policy.agree_m = 0.5;
  policy.agree_per_m = 0.05;
  FixFilter near(policy);
  near.Update(Answer(kTrue), Odometry(0));
  // 0.8 m apart after 2.5 m: 0.5 + 0.125 < 0.8, no agreement.
  EXPECT_EQ(near.Update(Answer(kTrue * Pose2(0.0, 0.8, 0.0)), Odometry(10)).status,
            FixStatus::kSearching);
  FixFilter far(policy);
  far.Update(Answer(kTrue), Odometry(0));
  // 0.8 m apart after 10 m: 0.5 + 0.5 > 0.8, agreement.
  EXPECT_EQ(far.Update(Answer(kTrue * Pose2(0.0, 0.8, 0.0)), Odometry(40)).status,
            FixStatus::kFixed);
}

TEST(FixFilter, OldAnswersAreForgotten) {
  FixPolicy policy;
  policy.window_m = 5.0;
  policy.weak_fix_span_m = 5.0;  // no longer than the window (Validate)
  FixFilter filter(policy);
  filter.Update(Answer(kTrue), Odometry(0));
  // 6 m later the first answer is gone: no fix from the second alone.
  EXPECT_EQ(filter.Update(Answer(kTrue), Odometry(24)).status, FixStatus::kSearching);
  EXPECT_EQ(filter.Update(Answer(kTrue), Odometry(28)).status, FixStatus::kFixed);
}

// A fix, then planted wrong answers.
class FixedFilter : public ::testing::Test {
 protected:
  void SetUp() override {
    filter_.Update(Answer(kTrue), Odometry(0));
    ASSERT_EQ(filter_.Update(Answer(kTrue), Odometry(5)).status, FixStatus::kFixed);
  }
  FixFilter filter_;
};

TEST_F(FixedFilter, APlantedWrongAnswerIsRejectedAndTheTrackKept) {
  const RelocalizationUpdate update = filter_.Update(Answer(kWrong, 0.6), Odometry(10));
  EXPECT_TRUE(update.contradicted);
  EXPECT_FALSE(update.lost);
  ASSERT_EQ(update.status, FixStatus::kFixed);
  const Pose2 expected = kTrue * Odometry(10);
  EXPECT_NEAR(update.T_world_robot.x, expected.x, 1e-9);
  EXPECT_NEAR(update.T_world_robot.y, expected.y, 1e-9);
  // A correct answer then confirms the track.
  EXPECT_TRUE(filter_.Update(Answer(kTrue), Odometry(15)).confirmed);
}

TEST_F(FixedFilter, AConfidentContradictionLosesTheFix) {
  const RelocalizationUpdate update = filter_.Update(Answer(kWrong, 0.95), Odometry(10));
  EXPECT_TRUE(update.lost);
  EXPECT_EQ(update.status, FixStatus::kLost);
  // The contradicting answer is a hypothesis: one more agreeing answer makes a new fix there.
  const RelocalizationUpdate refix = filter_.Update(Answer(kWrong, 0.5), Odometry(15));
  EXPECT_TRUE(refix.new_fix);
  EXPECT_EQ(refix.status, FixStatus::kFixed);
}

TEST_F(FixedFilter, AfterAConfidentContradictionTheOldFixCanBeRestored) {
  EXPECT_TRUE(filter_.Update(Answer(kWrong, 0.95), Odometry(10)).lost);
  const RelocalizationUpdate update = filter_.Update(Answer(kTrue, 0.5), Odometry(15));
  EXPECT_TRUE(update.new_fix);
  const Pose2 expected = kTrue * Odometry(15);
  EXPECT_NEAR(update.T_world_robot.x, expected.x, 1e-9);
}

TEST_F(FixedFilter, AConfirmationAveragesTheFixAndTheAnswer) {
  // The fix (one answer's uncertainty plus 1.25 m of drift) and an answer 0.4 m ahead weigh
  // about the same: the fix moves half way.
  const RelocalizationUpdate update =
      filter_.Update(Answer(kTrue * Pose2(0.4, 0.0, 0.0)), Odometry(10));
  ASSERT_TRUE(update.confirmed);
  const Pose2 shift = Between(kTrue * Odometry(10), update.T_world_robot);
  EXPECT_NEAR(shift.x, 0.2, 0.01);
  EXPECT_NEAR(shift.y, 0.0, 1e-9);
  // Many confirmations make the fix surer, but never surer than four answers: each new answer
  // still moves it by at least a fifth of its offset.
  for (int scan = 15; scan <= 100; scan += 5) filter_.Update(Answer(kTrue), Odometry(scan));
  const RelocalizationUpdate last =
      filter_.Update(Answer(kTrue * Pose2(0.5, 0.0, 0.0)), Odometry(105));
  const Pose2 moved = Between(kTrue * Odometry(105), last.T_world_robot);
  EXPECT_GE(moved.x, 0.5 / 5 - 1e-6);
  EXPECT_LT(moved.x, 0.25);
}

TEST_F(FixedFilter, ContradictionsThatAgreeReplaceTheFix) {
  filter_.Update(Answer(kWrong, 0.5), Odometry(10));
  const RelocalizationUpdate update = filter_.Update(Answer(kWrong, 0.5), Odometry(15));
  EXPECT_TRUE(update.lost);
  EXPECT_TRUE(update.new_fix);
  ASSERT_EQ(update.status, FixStatus::kFixed);
  const Pose2 expected = kWrong * Odometry(15);
  EXPECT_NEAR(update.T_world_robot.x, expected.x, 1e-9);
}

TEST_F(FixedFilter, NoConfirmationOverLostAfterLosesTheFix) {
  const int last_scan_kept = 5 + static_cast<int>(FixPolicy{}.lost_after_m / 0.25);
  for (int scan = 6; scan <= last_scan_kept; ++scan) {
    ASSERT_EQ(filter_.Update(std::nullopt, Odometry(scan)).status, FixStatus::kFixed) << scan;
  }
  const RelocalizationUpdate update = filter_.Update(std::nullopt, Odometry(last_scan_kept + 1));
  EXPECT_TRUE(update.lost);
  EXPECT_EQ(update.status, FixStatus::kLost);
}

TEST(FixFilter, OneConfirmationFixesAtOnce) {
  FixPolicy policy;
  policy.confirmations = 1;
  FixFilter filter(policy);
  EXPECT_TRUE(filter.Update(Answer(kTrue), Odometry(0)).new_fix);
}

// Weak answers second an accepted one from another look (more than agree_m of odometry away):
// alone, however many agree within a room's span (weak_fix_span_m), they make no fix.
TEST(FixFilter, WeakAnswersWithinARoomMakeNoFixAlone) {
  FixFilter filter;
  EXPECT_EQ(filter.Update(WeakAnswer(kTrue, 1), Odometry(0)).status, FixStatus::kSearching);
  EXPECT_EQ(filter.Update(WeakAnswer(kTrue, 2), Odometry(3)).status, FixStatus::kSearching);
  EXPECT_EQ(filter.Update(WeakAnswer(kTrue, 3), Odometry(8)).status, FixStatus::kSearching);
  const RelocalizationUpdate update = filter.Update(AnswerOfQuery(kTrue, 4), Odometry(16));
  ASSERT_EQ(update.status, FixStatus::kFixed);
  EXPECT_TRUE(update.new_fix);
  // The accepted answer and the three weak ones, each more than agree_m from it.
  EXPECT_NEAR(update.confidence, 1.0 - 0.5 * 0.95 * 0.95 * 0.95, 1e-12);
}

// Three weak answers of different looks that agree along more than weak_fix_span_m make a fix:
// the pose keeps explaining what the robot sees over a path longer than a room.
TEST(FixFilter, WeakAnswersAgreeingAlongAPathLongerThanARoomMakeAFix) {
  FixFilter filter;
  ASSERT_EQ(FixPolicy{}.weak_fix_answers, 3);
  ASSERT_EQ(FixPolicy{}.weak_fix_span_m, 10.0);
  EXPECT_EQ(filter.Update(WeakAnswer(kTrue, 1), Odometry(0)).status, FixStatus::kSearching);
  EXPECT_EQ(filter.Update(WeakAnswer(kTrue, 2), Odometry(20)).status, FixStatus::kSearching);
  // Three looks, but only 9.75 m from the first to the last.
  EXPECT_EQ(filter.Update(WeakAnswer(kTrue, 3), Odometry(39)).status, FixStatus::kSearching);
  const Pose2 latest = kTrue * Pose2(0.2, 0.0, 0.01);
  const RelocalizationUpdate update = filter.Update(WeakAnswer(latest, 4), Odometry(44));
  ASSERT_EQ(update.status, FixStatus::kFixed);
  EXPECT_TRUE(update.new_fix);
  EXPECT_NEAR(update.T_world_odom.x, latest.x, 1e-9);  // the newest answer's pose
  // Four weak answers of confidence 0.05 each: a fix of low confidence, as its evidence is.
  EXPECT_NEAR(update.confidence, 1.0 - std::pow(0.95, 4), 1e-12);
}

TEST(FixFilter, WeakAnswersThatDisagreeOrAreTooFewMakeNoFix) {
  // Two looks 12 m apart agree, a third in between names another pose.
  FixFilter filter;
  filter.Update(WeakAnswer(kTrue, 1), Odometry(0));
  filter.Update(WeakAnswer(kWrong, 2), Odometry(24));
  EXPECT_EQ(filter.Update(WeakAnswer(kTrue, 3), Odometry(48)).status, FixStatus::kSearching);
  // A third look that agrees completes them.
  EXPECT_TRUE(filter.Update(WeakAnswer(kTrue, 4), Odometry(56)).new_fix);

  // Off (0): weak answers only second accepted ones, however many and far apart.
  FixPolicy never;
  never.weak_fix_answers = 0;
  FixFilter off(never);
  for (int look = 0; look < 5; ++look) {
    EXPECT_EQ(off.Update(WeakAnswer(kTrue, look), Odometry(12 * look)).status,
              FixStatus::kSearching);
  }
}

// Two answers from nearly one spot (a robot turning on the spot) are one look, also when a third
// lies far from both.
TEST(FixFilter, WeakAnswersFromOneSpotAreOneLook) {
  FixFilter filter;
  filter.Update(WeakAnswer(kTrue, 1), Odometry(0));
  filter.Update(WeakAnswer(kTrue, 2), Odometry(2));  // 0.5 m on: the same look
  EXPECT_EQ(filter.Update(WeakAnswer(kTrue, 3), Odometry(44)).status, FixStatus::kSearching);
  EXPECT_TRUE(filter.Update(WeakAnswer(kTrue, 4), Odometry(50)).new_fix);
}

// A fix of weak answers alone that a confident answer contradicts stays a hypothesis as weak as it
// was: one more weak answer does not restore it, an accepted one does.
TEST(FixFilter, AContradictedWeakFixNeedsAnAcceptedAnswerBack) {
  FixFilter filter;
  filter.Update(WeakAnswer(kTrue, 1), Odometry(0));
  filter.Update(WeakAnswer(kTrue, 2), Odometry(20));
  ASSERT_TRUE(filter.Update(WeakAnswer(kTrue, 3), Odometry(44)).new_fix);
  ASSERT_TRUE(filter.Update(AnswerOfQuery(kWrong, 4, 0.95), Odometry(48)).lost);
  EXPECT_NE(filter.Update(WeakAnswer(kTrue, 5), Odometry(56)).status, FixStatus::kFixed);
  const RelocalizationUpdate update = filter.Update(AnswerOfQuery(kTrue, 6), Odometry(64));
  EXPECT_TRUE(update.new_fix);
  EXPECT_NEAR(update.T_world_odom.x, kTrue.x, 1e-9);
}

// An accepted answer among the looks never makes a fix harder than weak answers alone.
TEST(FixFilter, AnAcceptedLookCountsForTheWeakRuleToo) {
  FixPolicy policy;
  policy.confirmations = 4;
  FixFilter filter(policy);
  filter.Update(WeakAnswer(kTrue, 1), Odometry(0));
  filter.Update(AnswerOfQuery(kTrue, 2), Odometry(20));
  EXPECT_TRUE(filter.Update(WeakAnswer(kTrue, 3), Odometry(44)).new_fix);
}

TEST(FixFilter, AWeakAnswerFromAnotherLookSecondsAnAcceptedOne) {
  FixFilter filter;
  filter.Update(AnswerOfQuery(kTrue, 1), Odometry(0));
  // 0.5 m on: nearly the same look (a robot turning on the spot sees one room several times).
  EXPECT_EQ(filter.Update(WeakAnswer(kTrue, 2), Odometry(2)).status, FixStatus::kSearching);
  EXPECT_TRUE(filter.Update(WeakAnswer(kTrue, 3), Odometry(5)).new_fix);
}

TEST(FixFilter, AWeakAnswerThatDisagreesGivesNoFix) {
  FixFilter filter;
  filter.Update(AnswerOfQuery(kTrue, 1), Odometry(0));
  EXPECT_EQ(filter.Update(WeakAnswer(kWrong, 2), Odometry(8)).status, FixStatus::kSearching);
}

TEST(FixFilter, AWeakAnswerIsNoFixEvenWithOneConfirmation) {
  FixPolicy policy;
  policy.confirmations = 1;
  FixFilter filter(policy);
  EXPECT_EQ(filter.Update(WeakAnswer(kTrue, 1, 0.99), Odometry(0)).status, FixStatus::kSearching);
  EXPECT_TRUE(filter.Update(AnswerOfQuery(kTrue, 2), Odometry(8)).new_fix);
}

// A query's weak answer that its own later accepted answer contradicts does not make the query
// ambiguous (only accepted answers of one query that disagree do).
TEST(FixFilter, AnEarlierWeakAnswerOfTheQueryIsReplacedNotContradicted) {
  FixFilter filter;
  filter.Update(WeakAnswer(kWrong, 1), Odometry(0));
  const RelocalizationUpdate update = filter.Update(AnswerOfQuery(kTrue, 1), Odometry(4));
  EXPECT_FALSE(update.self_contradicted);
  EXPECT_TRUE(filter.Update(AnswerOfQuery(kTrue, 2), Odometry(8)).new_fix);
}

// A query that grows answers again every metre; scans added since its answer that let it name no
// place (more unmapped ground lowers its coverage) take nothing back from what its earlier scans
// said. Open halls (acapulco): an answer's query grows for about ten metres, most of them silent.
LocalizationResult SilentAnswerOfQuery(long long query_id) {
  LocalizationResult answer;
  answer.query_id = query_id;
  return answer;
}

TEST(FixFilter, ALaterSilenceOfTheQueryKeepsItsAnswer) {
  FixFilter filter;
  filter.Update(WeakAnswer(kTrue, 1), Odometry(0));
  filter.Update(SilentAnswerOfQuery(1), Odometry(4));
  filter.Update(SilentAnswerOfQuery(1), Odometry(8));
  ASSERT_EQ(filter.Beliefs().size(), 1U);
  const RelocalizationUpdate update = filter.Update(AnswerOfQuery(kTrue, 2), Odometry(12));
  EXPECT_TRUE(update.new_fix);
}

TEST(FixFilter, WeakAnswersKeptThroughSilencesAddUpAlongAPath) {
  FixFilter filter;
  filter.Update(WeakAnswer(kTrue, 1), Odometry(0));
  filter.Update(SilentAnswerOfQuery(1), Odometry(8));
  filter.Update(WeakAnswer(kTrue, 2), Odometry(20));
  filter.Update(SilentAnswerOfQuery(2), Odometry(28));
  EXPECT_TRUE(filter.Update(WeakAnswer(kTrue, 3), Odometry(44)).new_fix);  // 11 m from the first
}

// An ambiguous answer says the query sees a place that looks like another: what it said before
// is withdrawn.
TEST(FixFilter, ALaterAmbiguityOfTheQueryWithdrawsItsAnswer) {
  FixFilter filter;
  filter.Update(AnswerOfQuery(kTrue, 1), Odometry(0));
  LocalizationResult ambiguous = SilentAnswerOfQuery(1);
  ambiguous.ambiguous = true;
  filter.Update(ambiguous, Odometry(4));
  EXPECT_TRUE(filter.Beliefs().empty());
  EXPECT_EQ(filter.Update(AnswerOfQuery(kTrue, 2), Odometry(8)).status, FixStatus::kSearching);
}

// A query accepted at a pose, then weak at the same pose once it grew over ground the place lacks,
// still speaks as accepted: one weak answer of another query then makes the fix with it.
TEST(FixFilter, AQuerysWeakAnswerThatAgreesWithItsAcceptedOneKeepsItAccepted) {
  FixFilter filter;
  filter.Update(AnswerOfQuery(kTrue, 1), Odometry(0));
  filter.Update(WeakAnswer(kTrue * Pose2(0.1, 0.0, 0.0), 1), Odometry(20));
  EXPECT_TRUE(filter.Update(WeakAnswer(kTrue, 2), Odometry(40)).new_fix);
}

// Upheld, the accepted answer stays what it was: a later accepted answer of the query is judged
// against it, not against the weak pose (weak answers 0.9 m apart must not walk it away).
TEST(FixFilter, AnUpheldAcceptedAnswerKeepsItsOwnPose) {
  FixFilter filter;
  filter.Update(AnswerOfQuery(kTrue, 1), Odometry(0));
  filter.Update(WeakAnswer(kTrue * Pose2(0.9, 0.0, 0.0), 1), Odometry(4));
  const RelocalizationUpdate update =
      filter.Update(AnswerOfQuery(kTrue * Pose2(-0.2, 0.0, 0.0), 1), Odometry(8));
  EXPECT_FALSE(update.self_contradicted);
  ASSERT_EQ(filter.Beliefs().size(), 1U);
  EXPECT_NEAR(filter.Beliefs().front().x, (kTrue * Pose2(-0.2, 0.0, 0.0)).x, 1e-9);
}

// An accepted answer older than window_m is not upheld: the weak answer replaces it and counts as
// a weak look (with two more along 15 m, a fix).
TEST(FixFilter, AForgottenAcceptedAnswerIsNotUpheld) {
  FixFilter filter;
  filter.Update(AnswerOfQuery(kTrue, 1), Odometry(0));
  filter.Update(WeakAnswer(kTrue, 1), Odometry(100));  // 25 m on
  EXPECT_FALSE(filter.Update(WeakAnswer(kTrue, 2), Odometry(140)).new_fix);
  EXPECT_TRUE(filter.Update(WeakAnswer(kTrue, 3), Odometry(160)).new_fix);
}

// An ambiguous answer does not uphold its query's accepted one, even with a weak pose that agrees:
// that weak answer replaces it, so one more weak answer of another query is no fix.
TEST(FixFilter, AnAmbiguousAnswerDoesNotUpholdTheQuerysAcceptedOne) {
  FixFilter filter;
  filter.Update(AnswerOfQuery(kTrue, 1), Odometry(0));
  LocalizationResult ambiguous = WeakAnswer(kTrue, 1);
  ambiguous.ambiguous = true;
  filter.Update(ambiguous, Odometry(20));
  EXPECT_FALSE(filter.Update(WeakAnswer(kTrue, 2), Odometry(40)).new_fix);
}

// No weak answer because two distinct weak candidates tie is a look-alike, not silence.
TEST(FixFilter, ATieOfWeakCandidatesWithdrawsTheQuerysAnswer) {
  FixFilter filter;
  filter.Update(AnswerOfQuery(kTrue, 1), Odometry(0));
  LocalizationResult look_alike = SilentAnswerOfQuery(1);
  look_alike.match.weak_ambiguous = true;
  filter.Update(look_alike, Odometry(4));
  EXPECT_TRUE(filter.Beliefs().empty());
}

TEST(FixFilter, AQuerysWeakAnswerThatDisagreesWithItsAcceptedOneReplacesIt) {
  FixFilter filter;
  filter.Update(AnswerOfQuery(kTrue, 1), Odometry(0));
  filter.Update(WeakAnswer(kWrong, 1), Odometry(20));
  EXPECT_FALSE(filter.Update(WeakAnswer(kTrue, 2), Odometry(40)).new_fix);
  EXPECT_FALSE(filter.Update(WeakAnswer(kWrong, 3), Odometry(60)).new_fix);  // two weak looks
}

TEST_F(FixedFilter, AWeakAnswerConfirmsTheFix) {
  for (int scan = 6; scan < 40; ++scan) filter_.Update(std::nullopt, Odometry(scan));
  const RelocalizationUpdate update = filter_.Update(WeakAnswer(kTrue), Odometry(40));
  EXPECT_TRUE(update.confirmed);
  EXPECT_EQ(update.unconfirmed_m, 0.0);
}

// Along a corridor with doors at regular spacing weak answers from several looks can agree on one
// shifted pose: they never overturn a fix, however many and however confident.
TEST_F(FixedFilter, WeakContradictionsNeverOverturnTheFix) {
  for (int scan = 10; scan <= 30; scan += 5) {
    const RelocalizationUpdate update =
        filter_.Update(WeakAnswer(kWrong, scan, 0.95), Odometry(scan));
    EXPECT_TRUE(update.contradicted);
    EXPECT_FALSE(update.lost);
    ASSERT_EQ(update.status, FixStatus::kFixed);
    EXPECT_NEAR(update.T_world_odom.x, kTrue.x, 1e-9);
  }
  // An accepted challenger is not seconded by them either: one alone does not overturn the fix.
  EXPECT_FALSE(filter_.Update(AnswerOfQuery(kWrong, 99), Odometry(36)).lost);
}

TEST(FixFilter, RejectsInvalidPolicies) {
  FixPolicy policy;
  policy.confirmations = 0;
  EXPECT_THROW(FixFilter{policy}, std::invalid_argument);
  policy = {};
  policy.agree_m = -1.0;
  EXPECT_THROW(FixFilter{policy}, std::invalid_argument);
  policy = {};
  policy.contradiction_confidence = 1.5;
  EXPECT_THROW(FixFilter{policy}, std::invalid_argument);
  policy = {};
  policy.weak_fix_answers = -1;
  EXPECT_THROW(FixFilter{policy}, std::invalid_argument);
  policy = {};
  policy.weak_fix_span_m = -1.0;
  EXPECT_THROW(FixFilter{policy}, std::invalid_argument);
  policy = {};
  policy.weak_fix_span_m = policy.window_m + 1.0;  // answers are forgotten before
  EXPECT_THROW(FixFilter{policy}, std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
