#include "k4reg/project/pair_stage.h"

#include <algorithm>

#include "k4reg/project/partner_screen.h"
#include "k4reg/registration/ambiguity_margin.h"
#include "k4reg/util/stage_timing.h"

namespace k4reg {
namespace {

// The scans that no loop of the pairs registered so far confirms (a first loop selection, milliseconds).
std::vector<std::size_t> unconfirmed_scans(std::size_t scans, const RegisteredPairs& registered,
                                           const std::vector<ScanExtent>& extents) {
  const std::vector<ScanPair>& pairs = registered.pairs;
  const std::vector<PairOutcome>& outcomes = registered.outcomes;
  std::vector<LinkCandidates> found;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    ProjectLink scratch;
    found.push_back(link_from_outcome(outcomes[k], pairs[k], scratch));
  }
  const LoopSelectionResult selection = select_loop_consistent(found, extents);
  std::vector<bool> confirmed(scans, false);
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (selection.links[k].verdict == LinkVerdict::kConfirmed) confirmed[pairs[k].first] = confirmed[pairs[k].second] = true;
  std::vector<std::size_t> unconfirmed;
  for (std::size_t i = 0; i < scans; ++i)
    if (!confirmed[i]) unconfirmed.push_back(i);
  return unconfirmed;
}

// Registers the pairs that registered.pairs holds beyond its outcomes, wherever the runner sends them.
class PairRegistrar {
 public:
  PairRegistrar(const ProjectInputs& in, const PairCallback& on_pair, PairRunner* runner)
      : in_(in), on_pair_(on_pair), runner_(runner) {}

  void register_new(RegisteredPairs& registered) {
    std::vector<ScanPair>& pairs = registered.pairs;
    std::vector<PairOutcome>& outcomes = registered.outcomes;
    const std::size_t first = outcomes.size();
    const std::vector<ScanPair> batch(pairs.begin() + static_cast<std::ptrdiff_t>(first), pairs.end());
    outcomes.resize(pairs.size());
    (runner_ ? *runner_ : local_).run(in_.scans, batch, in_.pairwise, in_.cancel, [&](std::size_t k, PairOutcome outcome) {
      outcomes.at(first + k) = std::move(outcome);
      ProjectLink link;
      link_from_outcome(outcomes[first + k], pairs[first + k], link);
      if (on_pair_) on_pair_(link, done_, pairs.size());
      ++done_;
      if (in_.progress) in_.progress("pairs", static_cast<double>(done_) / pairs.size());
    });
  }

 private:
  const ProjectInputs& in_;
  const PairCallback& on_pair_;
  PairRunner* runner_;
  LocalPairRunner local_;
  std::size_t done_ = 0;
};

// 4PCS draws its bases in the source, so a pair's search can miss from one side a pose that the other side's
// bases find (a statuette view whose keypoints its neighbours do not repeat). The pairs of a scan that no loop
// confirms, where they found no well-supported pose, are searched again from the other side; a well-supported
// result from there replaces theirs, the link's source and target swapped. The dropped results' stage times are
// added to `timings`.
void search_unconfirmed_from_the_other_side(const ProjectInputs& in, PairRegistrar& registrar,
                                            RegisteredPairs& registered, std::vector<StageTiming>& timings) {
  std::vector<ScanPair>& pairs = registered.pairs;
  std::vector<PairOutcome>& outcomes = registered.outcomes;
  const std::vector<std::size_t> unconfirmed = unconfirmed_scans(in.scans.size(), registered, in.extents);
  auto doubtful = [&](std::size_t i) { return std::binary_search(unconfirmed.begin(), unconfirmed.end(), i); };
  std::vector<std::size_t> again;
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if ((doubtful(pairs[k].first) || doubtful(pairs[k].second)) &&
        !(outcomes[k].result && outcomes[k].result->well_supported))
      again.push_back(k);
  const std::size_t first_new = pairs.size();
  for (std::size_t k : again) pairs.emplace_back(pairs[k].second, pairs[k].first);
  if (!again.empty()) registrar.register_new(registered);
  for (std::size_t i = 0; i < again.size(); ++i) {
    PairOutcome& reverse = outcomes[first_new + i];
    PairOutcome& forward = outcomes[again[i]];
    const bool swap = reverse.result && reverse.result->well_supported;
    if (const PairOutcome& dropped = swap ? forward : reverse; dropped.result)  // its work still counts
      add_timings(timings, dropped.result->timings);
    reverse.seconds += forward.seconds;
    forward.seconds = reverse.seconds;
    if (swap) {
      pairs[again[i]] = pairs[first_new + i];
      forward = std::move(reverse);
    }
  }
  pairs.resize(first_new);
  outcomes.resize(first_new);
}

}  // namespace

RegisteredPairs register_pairs(const ProjectInputs& in, const ProjectParams& params, const PairCallback& on_pair,
                               PairRunner* runner, ProjectResult& result) {
  const std::size_t scans = in.scans.size();
  RegisteredPairs registered;
  // Large projects register each scan's best partners only, by a cheap overlap estimate of every pair.
  result.pairs_used = resolved(params.pairs, scans);
  std::vector<double> estimates;
  if (result.pairs_used == PairSelection::kScreened) {
    const StageTimer timer(result.timings, "screen");
    estimates = estimate_overlaps(in.scans, in.pairwise, in.cancel, in.progress);
    registered.pairs = best_partners(scans, estimates, params.partners);
    result.pairs_screened = estimates.size();
  } else {
    registered.pairs = candidate_pairs(scans, result.pairs_used, params.pair_list);
  }
  PairRegistrar registrar(in, on_pair, runner);
  registrar.register_new(registered);
  // A screened scan that no loop of its first pairs confirms gets its next best partners too, once: the loops
  // need them to check its links.
  if (result.pairs_used == PairSelection::kScreened) {
    const std::vector<std::size_t> extend = unconfirmed_scans(scans, registered, in.extents);
    const std::vector<ScanPair> more = more_partners(scans, estimates, registered.pairs, extend, params.partners);
    if (!more.empty()) {
      registered.pairs.insert(registered.pairs.end(), more.begin(), more.end());
      registrar.register_new(registered);
    }
  }
  search_unconfirmed_from_the_other_side(in, registrar, registered, result.timings);
  return registered;
}

std::vector<LinkCandidates> links_of_pairs(const RegisteredPairs& registered, ProjectResult& result) {
  std::vector<LinkCandidates> candidates;
  for (std::size_t k = 0; k < registered.pairs.size(); ++k) {
    ProjectLink& link = result.links.emplace_back();
    candidates.push_back(link_from_outcome(registered.outcomes[k], registered.pairs[k], link));
    if (registered.outcomes[k].result) add_timings(result.timings, registered.outcomes[k].result->timings);
  }
  return candidates;
}

LinkCandidates link_from_outcome(const PairOutcome& outcome, const ScanPair& pair, ProjectLink& link) {
  const auto [s, t] = pair;
  link.source = s;
  link.target = t;
  link.seconds = outcome.seconds;
  LinkCandidates c{s, t, {}, 0.0, false, 0.0, false, {}};
  if (!outcome.result) {
    link.verdict = LinkVerdict::kFailed;
    link.reason = outcome.error ? outcome.error->what() : "not registered";
    return c;
  }
  const RegistrationResult& result = *outcome.result;
  link.rmse_m = result.rmse_m;
  link.overlap = result.overlap;
  link.cloud_score = result.hypotheses.front().refined_score > 0 ? result.hypotheses.front().refined_score
                                                                 : result.hypotheses.front().cloud_score;
  link.ambiguity_margin = result.ambiguity_margin;
  link.ambiguous = result.ambiguous;
  link.well_supported = result.well_supported;
  link.min_scale_m_used = result.min_scale_m_used;
  link.overlap_used = result.overlap_used;
  link.constraint = result.constraint;
  link.reverse_judged = link.runner_up_preferred = false;
  link.reverse_margin = link.two_sided_margin = 0.0;
  c.transforms.push_back(result.transform);
  c.scores.push_back(link.cloud_score);
  // Runner-ups the free space contradicts outright (a score of 0 or less) cannot be the truth.
  for (std::size_t h = 1; h < result.hypotheses.size(); ++h) {
    const Hypothesis& hypothesis = result.hypotheses[h];
    if (hypothesis.cloud_score <= 0) continue;
    c.transforms.push_back(hypothesis.transform);
    c.scores.push_back(hypothesis.refined_score > 0 ? hypothesis.refined_score : hypothesis.cloud_score);
  }
  link.hypotheses = c.transforms.size();
  link.transform = result.transform;
  c.tolerance_m = link_tolerance_m(link);
  c.ambiguous = result.ambiguous;
  c.margin = margin_against_free_space_bar(result.ambiguity_margin, result.free_space_used);
  c.free_space_used = result.free_space_used;
  c.well_supported = result.well_supported;
  return c;
}

}  // namespace k4reg
