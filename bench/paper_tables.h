// The paper's numbers (Theiler, Wegner, Schindler 2014, Tables 2-4: real Z+F scans of a real lab and arch),
// printed beside ours for orientation only: our scenes are simulated look-alikes.
#pragma once

#include <cstddef>

namespace k4reg::bench {

// Table 2: keypoints per scan and success rate (%) of K-4PCS per minimum scale and scan size.
struct PaperCell {
  double sigma_mm;
  std::size_t points;
  int kp, sr;
};
constexpr PaperCell kPaperTable2[] = {
    {100, 700000, 1100, 91}, {100, 2500000, 1100, 95}, {100, 10000000, 1200, 95},
    {50, 700000, 2800, 98},  {50, 2500000, 2800, 98},  {50, 10000000, 3200, 98},
    {25, 700000, 5900, 98},  {25, 2500000, 6800, 97},  {25, 10000000, 8200, 100},
};

// Tables 3 and 4: 4PCS against K-4PCS per minimum scale.
struct PaperComparison {
  double sigma_mm;
  const char* four_pcs;   // SR / RMSE / T of 4PCS
  const char* k4pcs;      // SR / RMSE / T (/ KP) of K-4PCS
};
constexpr PaperComparison kPaperTable3[] = {{100, "4 % / 0.66 m / 18 s (900 mm grid)", "91 % / 0.15 m / 8 s"},
                                            {50, "35 % / 0.46 m / 589 s (500 mm grid)", "98 % / 0.06 m / 41 s"},
                                            {25, "62 % / 0.28 m / 9637 s (350 mm grid)", "98 % / 0.04 m / 102 s"}};
constexpr PaperComparison kPaperTable4[] = {
    {100, "10 % / 0.80 m / 652 s (1500 mm grid)", "57 % / 0.52 m / 182 s / KP 2900"},
    {50, "30 % / 0.79 m / 9800 s (1000 mm grid)", "100 % / 0.40 m / 663 s / KP 6000"},
    {25, "N.A. (> 72 h)", "83 % / 0.17 m / 2047 s / KP 10400"}};

}  // namespace k4reg::bench
