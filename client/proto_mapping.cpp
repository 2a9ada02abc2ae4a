#include "proto_mapping.h"

namespace k4reg::cli {
namespace {

bool given(const CLI::Option* flag) { return flag->count() > 0; }

v1::KeypointSignal signal_to_proto(KeypointSignal signal) {
  switch (signal) {
    case KeypointSignal::kAuto: return v1::KEYPOINT_SIGNAL_AUTO;
    case KeypointSignal::kIntensity: return v1::KEYPOINT_SIGNAL_INTENSITY;
    case KeypointSignal::kGeometric: return v1::KEYPOINT_SIGNAL_GEOMETRIC;
  }
  return v1::KEYPOINT_SIGNAL_UNSPECIFIED;
}

v1::FreeSpaceCheck free_space_to_proto(FreeSpaceCheck check) {
  switch (check) {
    case FreeSpaceCheck::kAuto: return v1::FREE_SPACE_CHECK_AUTO;
    case FreeSpaceCheck::kOn: return v1::FREE_SPACE_CHECK_ON;
    case FreeSpaceCheck::kOff: return v1::FREE_SPACE_CHECK_OFF;
  }
  return v1::FREE_SPACE_CHECK_UNSPECIFIED;
}

v1::CoarseMethod method_to_proto(CoarseMethod method) {
  switch (method) {
    case CoarseMethod::kKeypoint4pcs: return v1::COARSE_METHOD_KEYPOINT_4PCS;
    case CoarseMethod::kPlain4pcs: return v1::COARSE_METHOD_PLAIN_4PCS;
  }
  return v1::COARSE_METHOD_UNSPECIFIED;
}

}  // namespace

v1::RegistrationParams params_to_proto(const RegistrationParams& p, const RegistrationFlags& flags) {
  v1::RegistrationParams m;
  if (given(flags.min_scale)) m.set_min_scale_m(p.min_scale_m);
  if (given(flags.overlap)) m.set_overlap(p.overlap);
  if (given(flags.no_icp)) m.set_icp(p.icp);
  if (given(flags.levelled)) m.set_levelled(p.levelled);
  if (given(flags.seed)) m.set_seed(p.seed);
  if (given(flags.threads)) m.set_threads(p.threads);
  if (given(flags.time_budget)) m.set_time_budget_s(p.time_budget_s);
  if (given(flags.bases)) m.set_max_bases(p.max_bases);
  if (given(flags.octaves)) m.set_octaves(p.octaves);
  if (given(flags.scales_per_octave)) m.set_scales_per_octave(p.scales_per_octave);
  if (given(flags.min_contrast)) m.set_min_contrast(p.min_contrast);
  if (given(flags.signal)) m.set_signal(signal_to_proto(p.signal));
  if (given(flags.free_space)) m.set_free_space(free_space_to_proto(p.free_space));
  if (given(flags.method)) m.set_method(method_to_proto(p.method));
  if (given(flags.plain_voxel)) m.set_plain_voxel_m(p.plain_voxel_m);
  return m;
}

}  // namespace k4reg::cli
