// Which scan pairs a project registers. Every pair costs one pairwise registration (about 0.2-3 s), so
// this sets the project's cost: all pairs is N(N-1)/2 (66 for 12 scans, 1225 for 50), a sequence 2N-3
// (the scans as acquired, each with the next two), each scan's best partners after a cheap screen of every pair
// (partner_screen.h: at most kN), or a list the user gives.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace k4reg {

enum class PairSelection {
  kAll,       // every pair: the most loops to check
  kSequence,  // i with i+1, and i with i+2, so that every three consecutive scans close a loop
  kList,      // ProjectParams::pair_list
  kScreened,  // each scan's best partners by a cheap overlap estimate of every pair (partner_screen.h)
  kAuto,      // all pairs up to kAllPairsUpTo scans, screened beyond
};

// Up to this many scans (120 pairs) kAuto registers every pair; beyond, the screen's cost (a tenth of a pair's
// each) and the pairs it saves pay off.
constexpr std::size_t kAllPairsUpTo = 16;

// The selection kAuto stands for with this many scans; any other selection as given.
PairSelection resolved(PairSelection selection, std::size_t scans);

// "all", "sequence", "list", "screened", "auto".
const char* to_string(PairSelection selection);

// The selection with that name (to_string's), if any.
std::optional<PairSelection> pair_selection_named(std::string_view name);

using ScanPair = std::pair<std::size_t, std::size_t>;

// The pairs to register for the selections that need no data (all, sequence, list), each once (low index
// first), in a fixed order. kInvalidArgument for a listed pair out of range or of a scan with itself, and for
// kScreened / kAuto (they need the scans: partner_screen.h); duplicates in a list are dropped.
std::vector<ScanPair> candidate_pairs(std::size_t scans, PairSelection selection, const std::vector<ScanPair>& list = {});

// Reads a pair list: one pair of 0-based scan indices per line ("0 3" or "0,3"), '#' comments. kNotFound /
// kInvalidArgument naming the file and line.
std::vector<ScanPair> read_pair_list(const std::string& path);

}  // namespace k4reg
