// The field tables of LocalizerConfig and its FixPolicy (docs in global_localizer.hpp).

#include "localization/localization_fields.hpp"

namespace keyplace {

namespace {

const ConfigFields<FixPolicy>& FixPolicyFields() {
  using C = FixPolicy;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("FixPolicy");
    table
        .Int("confirmations", &C::confirmations, "",
             "answers that must agree through odometry before a fix (one accepted)")
        .Int("weak_fix_answers", &C::weak_fix_answers, "",
             "weak answers alone make a fix when this many agree through odometry (0 = never) "
             "...")
        .Double("weak_fix_span_m", &C::weak_fix_span_m, "m",
                "... from looks this far apart (odometry), first to last")
        .Double("agree_m", &C::agree_m, "m", "two answers agree within this distance (now) ...")
        .Double("agree_per_m", &C::agree_per_m, "m/m",
                "... plus this per metre travelled between them (odometry drift)")
        .Double("agree_deg", &C::agree_deg, "deg", "... and this angle")
        .Double("window_m", &C::window_m, "m",
                "answers older than this odometry distance are forgotten while searching")
        .Double("lost_after_m", &C::lost_after_m, "m",
                "a fix no answer confirmed over this odometry distance is lost")
        .Double("contradiction_confidence", &C::contradiction_confidence, "",
                "one accepted answer this confident contradicting the fix loses it at once")
        .Double("track_check_every_m", &C::track_check_every_m, "m",
                "while fixed, check every this much odometry that the latest scans fit the map "
                "at the fix; a misfit loses it (0 = off)")
        .Double("map_sigma_m", &C::map_sigma_m, "m",
                "the map's own position error, added to a fix's covariance from the matches")
        .Double("map_sigma_deg", &C::map_sigma_deg, "deg",
                "the map's own heading error, added likewise");
    return table;
  }();
  return fields;
}

}  // namespace

const ConfigFields<LocalizerConfig>& LocalizerConfigFields() {
  using C = LocalizerConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("LocalizerConfig");
    table
        .Int("max_query_scans", &C::max_query_scans, "",
             "a query submap not complete after this many scans is recognised as it stands")
        .Double("query_every_m", &C::query_every_m, "m",
                "also answer from the query as it stands every time the robot travelled this far "
                "(0 = only complete queries)")
        .Double("search_near_m", &C::search_near_m, "m",
                "retrieval words, or auto while a fix is held: queries also pair the places this "
                "close to where a pending answer or the fix puts the robot (0 = words alone)")
        .Double("map_search_window_m", &C::map_search_window_m, "m",
                "without a fix, search the whole map with the beams of the scans over at most this "
                "much odometry (0 = never) ...")
        .Double("map_search_every_m", &C::map_search_every_m, "m",
                "... every time the robot travelled this far")
        .Double("map_search_margin", &C::map_search_margin, "",
                "... a pose is an answer when its mean closeness beats every distinct pose's by "
                "this")
        .Nested("fix", &C::fix, FixPolicyFields());
    return table;
  }();
  return fields;
}

}  // namespace keyplace
