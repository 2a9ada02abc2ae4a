// The margin a verdict needs between its best pose and the runner-up, by the evidence it rests on.
// With the scanners' free space (or the cameras' views), a true pose explains 0.95-1.00 of what the target saw and
// a twin clearly less, so kAmbiguousMargin separates them. On geometry alone (clouds with no known
// scanner: merged, resampled, multi-beam; or --free-space off) a symmetric room's half-turn twin can explain more
// of the source than the truth does: on the blind protocol's tuning pairs with free space off, wrong poses won by
// margins up to 0.16 (held out: 0.13), right ones by 0.05 to 0.5. There a runner-up anywhere in the contender
// band (within a fifth of the best's support, the hypotheses the verdict refines) leaves the result ambiguous.
#pragma once

namespace k4reg {

// Below this margin between the best pose and the runner-up, a result judged with free space is flagged ambiguous.
constexpr double kAmbiguousMargin = 0.05;

constexpr double kGeometryOnlyAmbiguousMargin = 0.2;

// kAmbiguousMargin where the free space judged the poses, else kGeometryOnlyAmbiguousMargin.
constexpr double ambiguous_below(bool free_space_used) {
  return free_space_used ? kAmbiguousMargin : kGeometryOnlyAmbiguousMargin;
}

// A margin as it weighs against kAmbiguousMargin in a project's rules (loops that vouch, two-sided margins, how
// firmly links hold a scan), which add the margins of independent links. Free-space margins are independent
// evidence. On geometry alone a margin under kGeometryOnlyAmbiguousMargin is none: a symmetric scene's twin wins
// such margins systematically (the same half turn in every pair of the hall, so three links at 0.1 each, or a loop
// of two, would add up to a confident wrong placement); above it, it counts scaled by the ratio of the two bars.
constexpr double margin_against_free_space_bar(double margin, bool free_space_used) {
  if (free_space_used) return margin;
  const bool under_the_bar = margin < kGeometryOnlyAmbiguousMargin && margin > -kGeometryOnlyAmbiguousMargin;
  return under_the_bar ? 0.0 : margin * kAmbiguousMargin / kGeometryOnlyAmbiguousMargin;
}

// Score a's margin over score b, (a - b) / max(a, b) (0 where neither scores), against the free-space bar.
constexpr double score_margin(double a, double b, bool free_space_used) {
  const double larger = a > b ? a : b;
  return larger > 0 ? margin_against_free_space_bar((a - b) / larger, free_space_used) : 0.0;
}

}  // namespace k4reg
