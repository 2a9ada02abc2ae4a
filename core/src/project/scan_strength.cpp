#include "k4reg/project/scan_strength.h"

#include <algorithm>
#include <deque>
#include <limits>

namespace k4reg {

std::vector<double> scan_strengths(std::size_t scans, const std::vector<WeightedLink>& links, std::size_t reference,
                                   double cap) {
  // Undirected capacities as a dense matrix: projects have at most a few hundred scans.
  std::vector<double> capacity(scans * scans, 0.0);
  for (const WeightedLink& l : links)
    if (l.a != l.b && l.a < scans && l.b < scans) {
      capacity[l.a * scans + l.b] += l.weight;
      capacity[l.b * scans + l.a] += l.weight;
    }
  std::vector<double> strength(scans, 0.0);
  for (std::size_t target = 0; target < scans; ++target) {
    if (target == reference) {
      strength[target] = cap;
      continue;
    }
    // Edmonds-Karp from the reference, until no path is left or the flow reaches the cap.
    std::vector<double> residual = capacity;
    double flow = 0.0;
    while (flow < cap) {
      std::vector<std::size_t> parent(scans, scans);
      parent[reference] = reference;
      std::deque<std::size_t> queue{reference};
      while (!queue.empty() && parent[target] == scans) {
        const std::size_t u = queue.front();
        queue.pop_front();
        for (std::size_t v = 0; v < scans; ++v)
          if (parent[v] == scans && residual[u * scans + v] > 1e-12) parent[v] = u, queue.push_back(v);
      }
      if (parent[target] == scans) break;
      double push = cap - flow;
      for (std::size_t v = target; v != reference; v = parent[v]) push = std::min(push, residual[parent[v] * scans + v]);
      for (std::size_t v = target; v != reference; v = parent[v]) {
        residual[parent[v] * scans + v] -= push;
        residual[v * scans + parent[v]] += push;
      }
      flow += push;
    }
    strength[target] = std::min(flow, cap);
  }
  return strength;
}

}  // namespace k4reg
