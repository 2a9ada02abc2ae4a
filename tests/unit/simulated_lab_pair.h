// Lab stations 0 and 2 of the scan simulator (60 000 points each), simulated once per test program: a small pair
// that registers in about a second. Used by survey_coordinates_test and the service's scan-format test.
#pragma once

#include <vector>

#include "sim/scanner.h"
#include "sim/scene.h"

namespace k4reg::test {

// station: 0 (the source of the pair) or 2 (the target).
inline const sim::SimulatedScan& lab_scan(int station) {
  static const std::vector<sim::SimulatedScan> scans = [] {
    sim::ScanParams params;
    params.points = 60000;
    const sim::Scene lab = sim::make_scene("lab");
    return std::vector<sim::SimulatedScan>{sim::simulate_scan(lab, 0, params), sim::simulate_scan(lab, 2, params)};
  }();
  return scans[station == 0 ? 0 : 1];
}

}  // namespace k4reg::test
