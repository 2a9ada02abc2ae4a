#include "k4reg/project/scan_strength.h"

#include <algorithm>
#include <deque>

namespace k4reg {
namespace {

constexpr double kNoCapacity = 1e-12;

// Breadth-first over the residual capacities from `from`: each scan's predecessor, `scans` where unreached.
std::vector<std::size_t> reach(std::size_t scans, const std::vector<double>& residual, std::size_t from,
                               std::size_t stop_at) {
  std::vector<std::size_t> parent(scans, scans);
  parent[from] = from;
  std::deque<std::size_t> queue{from};
  while (!queue.empty() && parent[stop_at] == scans) {
    const std::size_t u = queue.front();
    queue.pop_front();
    for (std::size_t v = 0; v < scans; ++v)
      if (parent[v] == scans && residual[u * scans + v] > kNoCapacity) parent[v] = u, queue.push_back(v);
  }
  return parent;
}

}  // namespace

std::vector<ScanHold> scan_holds(std::size_t scans, const std::vector<WeightedLink>& links, std::size_t reference,
                                 double cap) {
  // Undirected capacities as a dense matrix: projects have at most a few hundred scans.
  std::vector<double> capacity(scans * scans, 0.0);
  for (const WeightedLink& l : links)
    if (l.a != l.b && l.a < scans && l.b < scans) {
      capacity[l.a * scans + l.b] += l.weight;
      capacity[l.b * scans + l.a] += l.weight;
    }
  std::vector<ScanHold> holds(scans);
  for (std::size_t target = 0; target < scans; ++target) {
    if (target == reference) {
      holds[target].strength = cap;
      continue;
    }
    // Edmonds-Karp from the reference, until no path is left or the flow reaches the cap.
    std::vector<double> residual = capacity;
    double flow = 0.0;
    bool cut = false;
    while (flow < cap) {
      const std::vector<std::size_t> parent = reach(scans, residual, reference, target);
      if (parent[target] == scans) {
        cut = true;
        break;
      }
      double push = cap - flow;
      for (std::size_t v = target; v != reference; v = parent[v]) push = std::min(push, residual[parent[v] * scans + v]);
      for (std::size_t v = target; v != reference; v = parent[v]) {
        residual[parent[v] * scans + v] -= push;
        residual[v * scans + parent[v]] += push;
      }
      flow += push;
    }
    holds[target].strength = std::min(flow, cap);
    if (!cut) continue;
    // The minimum cut: what the reference still reaches stays; the rest moves with the scan.
    const std::vector<std::size_t> stays = reach(scans, residual, reference, target);
    for (std::size_t v = 0; v < scans; ++v)
      if (stays[v] == scans) holds[target].moves_with.push_back(v);
  }
  return holds;
}

}  // namespace k4reg
