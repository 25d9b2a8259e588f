#include "io/tf_tree.hpp"

#include <algorithm>
#include <utility>

#include "common/shown_text.hpp"

namespace keyplace {

std::string NormalizeFrame(const std::string& frame) {
  const auto first = frame.find_first_not_of('/');
  return first == std::string::npos ? std::string() : frame.substr(first);
}

void TfTree::Add(const std::string& parent, const std::string& child, double stamp_s,
                 const Pose2& T_parent_child, bool is_static) {
  auto [it, inserted] = edge_of_child_.try_emplace(NormalizeFrame(child));
  Edge& edge = it->second;
  if (inserted) edge.parent = NormalizeFrame(parent);
  if (edge.parent != NormalizeFrame(parent)) return;
  if (is_static) {
    edge.static_pose = T_parent_child;
  } else {
    edge.samples.push_back({stamp_s, T_parent_child});
    edge.track.reset();
  }
}

std::optional<std::vector<const TfTree::Edge*>> TfTree::Chain(const std::string& ancestor,
                                                              const std::string& frame) const {
  std::vector<const Edge*> chain;
  std::string current = NormalizeFrame(frame);
  const std::string top = NormalizeFrame(ancestor);
  // A tree has fewer edges than frames; more steps than edges means a cycle.
  while (current != top) {
    const auto it = edge_of_child_.find(current);
    if (it == edge_of_child_.end() || chain.size() > edge_of_child_.size()) return std::nullopt;
    chain.push_back(&it->second);
    current = it->second.parent;
  }
  return chain;
}

std::optional<Pose2> TfTree::Lookup(const std::string& ancestor, const std::string& frame,
                                    double stamp_s, TrackPosition* position) const {
  const auto chain = Chain(ancestor, frame);
  if (!chain) return std::nullopt;
  TrackPosition overall;
  Pose2 T_ancestor_frame;
  // The chain runs from `frame` upwards: each edge's pose goes on the left.
  for (const Edge* edge : *chain) {
    Pose2 T_parent_child;
    if (!edge->samples.empty()) {
      if (!edge->track) edge->track = PoseTrack(edge->samples);
      TrackPosition where;
      T_parent_child = edge->track->At(stamp_s, &where);
      overall.before_first = overall.before_first || where.before_first;
      overall.after_last = overall.after_last || where.after_last;
      overall.gap_s = std::max(overall.gap_s, where.gap_s);
    } else {
      T_parent_child = *edge->static_pose;
    }
    T_ancestor_frame = T_parent_child * T_ancestor_frame;
  }
  if (position != nullptr) *position = overall;
  return T_ancestor_frame;
}

std::vector<double> TfTree::ChainStamps(const std::string& ancestor,
                                        const std::string& frame) const {
  std::vector<double> stamps;
  const auto chain = Chain(ancestor, frame);
  if (!chain) return stamps;
  for (const Edge* edge : *chain) {
    for (const StampedPose& sample : edge->samples) stamps.push_back(sample.stamp_s);
  }
  std::sort(stamps.begin(), stamps.end());
  stamps.erase(std::unique(stamps.begin(), stamps.end()), stamps.end());
  return stamps;
}

std::string TfTree::Describe() const {
  if (edge_of_child_.empty()) return "no transforms";
  // Bounded: frame ids come from the bag, and a message must not grow with them.
  constexpr std::size_t kShown = 20;
  std::string text;
  std::size_t shown = 0;
  for (const auto& [child, edge] : edge_of_child_) {
    if (shown++ == kShown) {
      text += ", and " + std::to_string(edge_of_child_.size() - kShown) + " more";
      break;
    }
    text += (text.empty() ? "" : ", ") + ShownText(edge.parent) + " -> " + ShownText(child) +
            (edge.samples.empty() ? " (static)" : "");
  }
  return text;
}

}  // namespace keyplace
