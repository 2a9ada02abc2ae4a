#include "remote/proto_mapping.h"

#include "enum_convert.h"

namespace k4reg::cli {
namespace {

bool given(const CLI::Option* flag) { return flag->count() > 0; }

}  // namespace

v1::RegistrationParams params_to_proto(const RegistrationParams& p, const RegistrationFlags& flags) {
  v1::RegistrationParams m;
  if (given(flags.min_scale)) m.set_min_scale_m(p.min_scale_m);
  if (given(flags.overlap)) m.set_overlap(p.overlap);
  if (given(flags.no_icp)) m.set_icp(p.icp);
  if (given(flags.one_sided)) m.set_search_other_side(p.search_other_side);
  if (given(flags.levelled)) m.set_levelled(p.levelled);
  if (given(flags.seed)) m.set_seed(p.seed);
  if (given(flags.threads)) m.set_threads(p.threads);
  if (given(flags.time_budget)) m.set_time_budget_s(p.time_budget_s);
  if (given(flags.bases)) m.set_max_bases(p.max_bases);
  if (given(flags.octaves)) m.set_octaves(p.octaves);
  if (given(flags.scales_per_octave)) m.set_scales_per_octave(p.scales_per_octave);
  if (given(flags.min_contrast)) m.set_min_contrast(p.min_contrast);
  if (given(flags.signal)) m.set_signal(api::to_proto(p.signal));
  if (given(flags.free_space)) m.set_free_space(api::to_proto(p.free_space));
  if (given(flags.method)) m.set_method(api::to_proto(p.method));
  if (given(flags.plain_voxel)) m.set_plain_voxel_m(p.plain_voxel_m);
  return m;
}

}  // namespace k4reg::cli
