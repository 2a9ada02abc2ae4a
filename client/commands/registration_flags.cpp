#include "commands/registration_flags.h"

#include <map>

namespace k4reg::cli {

RegistrationFlags add_registration_flags(CLI::App& command, RegistrationParams& params) {
  RegistrationFlags flags{};
  flags.min_scale =
      command
          .add_option("--min-scale", params.min_scale_m,
                      "minimum DoG scale sigma and voxel spacing, in the files' units (default: from the scans' "
                      "sampling; halved while a scale finds too few keypoints or no well-supported pose)")
          ->check(CLI::Range(0.001, 10.0));
  flags.overlap = command
                      .add_option("--overlap", params.overlap,
                                  "approximate overlap of the two scans, [0.05, 1] (default: automatic, bases for "
                                  "0.8, then 0.6, then 0.4 until a pose is well supported)")
                      ->check(CLI::Range(0.05, 1.0));
  flags.no_icp = command.add_flag("--no-icp{false}", params.icp, "skip the ICP refinement (coarse K-4PCS result only)");
  flags.one_sided = command.add_flag(
      "--one-sided{false}", params.search_other_side,
      "search each pair from the source's side only (by default a scale that finds no well-supported pose "
      "searches the pair again with the scans swapped)");
  flags.levelled = command.add_flag("--levelled", params.levelled,
                                    "the scanners were levelled (z axes vertical, as a tilt compensator makes them): "
                                    "only rotations about z are searched and refined");
  flags.seed = command.add_option("--seed", params.seed, "random seed; the same seed gives the same result")
                   ->capture_default_str();
  flags.threads = command.add_option("--threads", params.threads, "worker threads, 0 = all cores")
                      ->capture_default_str()
                      ->check(CLI::Range(0, 1024));
  flags.time_budget =
      command.add_option("--time-budget", params.time_budget_s, "give up after this many seconds, 0 = no limit")
          ->capture_default_str()
          ->check(CLI::NonNegativeNumber);
  flags.bases = command.add_option("--bases", params.max_bases, "number of 4PCS bases L, 0 = from the overlap")
                    ->capture_default_str()
                    ->check(CLI::Range(0, 1000000));
  flags.octaves =
      command.add_option("--octaves", params.octaves, "DoG octaves")->capture_default_str()->check(CLI::Range(1, 8));
  flags.scales_per_octave =
      command.add_option("--scales-per-octave", params.scales_per_octave, "DoG scales per octave")
          ->capture_default_str()
          ->check(CLI::Range(1, 10));
  flags.min_contrast =
      command.add_option("--min-contrast", params.min_contrast, "DoG minimum contrast, fraction of the signal range")
          ->capture_default_str()
          ->check(CLI::Range(0.0, 0.99));
  const std::map<std::string, KeypointSignal> signals{{"auto", KeypointSignal::kAuto},
                                                      {"intensity", KeypointSignal::kIntensity},
                                                      {"geometric", KeypointSignal::kGeometric}};
  flags.signal = command.add_option("--signal", params.signal, "keypoint signal: auto, intensity or geometric")
                     ->transform(CLI::CheckedTransformer(signals, CLI::ignore_case));
  const std::map<std::string, FreeSpaceCheck> free_space{
      {"auto", FreeSpaceCheck::kAuto}, {"on", FreeSpaceCheck::kOn}, {"off", FreeSpaceCheck::kOff}};
  flags.free_space =
      command
          .add_option("--free-space", params.free_space,
                      "judge poses by the scanners' free space: auto (terrestrial scans whose scanner position is "
                      "known: from the file, the frame's origin or the scan's sampling; or single object views), on "
                      "(the scanner positions known, else the frames' origins) or off (geometry alone)")
          ->transform(CLI::CheckedTransformer(free_space, CLI::ignore_case));
  const std::map<std::string, CoarseMethod> methods{{"k4pcs", CoarseMethod::kKeypoint4pcs},
                                                    {"4pcs", CoarseMethod::kPlain4pcs}};
  flags.method =
      command
          .add_option("--method", params.method, "coarse method: k4pcs (keypoints) or 4pcs (plain, on a coarse grid)")
          ->transform(CLI::CheckedTransformer(methods, CLI::ignore_case));
  flags.plain_voxel =
      command.add_option("--plain-voxel", params.plain_voxel_m, "voxel spacing for --method 4pcs, 0 = automatic")
          ->check(CLI::Range(0.0, 100.0));
  return flags;
}

}  // namespace k4reg::cli
