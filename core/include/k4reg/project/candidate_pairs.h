// Which scan pairs a project registers. Every pair costs one pairwise registration (about 0.2-3 s), so
// this sets the project's cost: all pairs is N(N-1)/2 (66 for 12 scans, 1225 for 50), a sequence N-1
// (the scans as acquired, each with the next; no loops, so no loop checks), or a list the user gives.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace k4reg {

enum class PairSelection {
  kAll,       // every pair: the most loops to check
  kSequence,  // i with i+1, and i with i+2, so that every three consecutive scans close a loop
  kList,      // ProjectParams::pair_list
};

using ScanPair = std::pair<std::size_t, std::size_t>;

// The pairs to register, each once (low index first), in a fixed order. kInvalidArgument for a listed pair
// out of range or of a scan with itself; duplicates in a list are dropped.
std::vector<ScanPair> candidate_pairs(std::size_t scans, PairSelection selection, const std::vector<ScanPair>& list = {});

// Reads a pair list: one pair of 0-based scan indices per line ("0 3" or "0,3"), '#' comments. kNotFound /
// kInvalidArgument naming the file and line.
std::vector<ScanPair> read_pair_list(const std::string& path);

}  // namespace k4reg
