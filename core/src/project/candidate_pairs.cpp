#include "k4reg/project/candidate_pairs.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "k4reg/util/error.h"

namespace k4reg {

std::vector<ScanPair> candidate_pairs(std::size_t scans, PairSelection selection, const std::vector<ScanPair>& list) {
  std::vector<ScanPair> pairs;
  switch (selection) {
    case PairSelection::kAll:
      for (std::size_t i = 0; i < scans; ++i)
        for (std::size_t j = i + 1; j < scans; ++j) pairs.emplace_back(i, j);
      break;
    case PairSelection::kSequence:
      for (std::size_t i = 0; i + 1 < scans; ++i) {
        pairs.emplace_back(i, i + 1);
        if (i + 2 < scans) pairs.emplace_back(i, i + 2);
      }
      break;
    case PairSelection::kList:
      for (auto [a, b] : list) {
        if (a >= scans || b >= scans)
          fail(ErrorCode::kInvalidArgument, "pair " + std::to_string(a) + " " + std::to_string(b) + " names a scan beyond the " +
                                                std::to_string(scans) + " given (indices start at 0)");
        if (a == b) fail(ErrorCode::kInvalidArgument, "pair " + std::to_string(a) + " " + std::to_string(b) + " pairs a scan with itself");
        pairs.emplace_back(std::min(a, b), std::max(a, b));
      }
      std::sort(pairs.begin(), pairs.end());
      pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
      break;
    case PairSelection::kScreened:
    case PairSelection::kAuto:
      fail(ErrorCode::kInvalidArgument, std::string("pairs ") + to_string(selection) + " need the scans (partner_screen.h)");
  }
  return pairs;
}

PairSelection resolved(PairSelection selection, std::size_t scans) {
  if (selection != PairSelection::kAuto) return selection;
  return scans <= kAllPairsUpTo ? PairSelection::kAll : PairSelection::kScreened;
}

const char* to_string(PairSelection selection) {
  switch (selection) {
    case PairSelection::kAll: return "all";
    case PairSelection::kSequence: return "sequence";
    case PairSelection::kList: return "list";
    case PairSelection::kScreened: return "screened";
    case PairSelection::kAuto: return "auto";
  }
  return "?";
}

std::optional<PairSelection> pair_selection_named(std::string_view name) {
  for (PairSelection selection : {PairSelection::kAll, PairSelection::kSequence, PairSelection::kList,
                                  PairSelection::kScreened, PairSelection::kAuto})
    if (name == to_string(selection)) return selection;
  return std::nullopt;
}

std::vector<ScanPair> read_pair_list(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(ErrorCode::kNotFound, path + ": cannot open the pair list");
  std::vector<ScanPair> pairs;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    line = line.substr(0, line.find('#'));
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    long long a = 0, b = 0;
    std::string rest;
    if (!(fields >> a)) continue;  // blank or comment
    if (!(fields >> b) || (fields >> rest) || a < 0 || b < 0)
      fail(ErrorCode::kInvalidArgument, path + ":" + std::to_string(number) + ": expected two scan indices (\"0 3\")");
    pairs.emplace_back(static_cast<std::size_t>(a), static_cast<std::size_t>(b));
  }
  return pairs;
}

}  // namespace k4reg
