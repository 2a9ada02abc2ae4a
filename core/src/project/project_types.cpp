#include "k4reg/project/project_types.h"

#include <array>
#include <utility>

#include "k4reg/util/error.h"

namespace k4reg {
namespace {

constexpr std::array<std::pair<LinkVerdict, const char*>, 8> kNames{{
    {LinkVerdict::kConfirmed, "confirmed"},
    {LinkVerdict::kConsistent, "consistent"},
    {LinkVerdict::kUnchecked, "unchecked"},
    {LinkVerdict::kContradicted, "contradicted"},
    {LinkVerdict::kUnresolved, "unresolved"},
    {LinkVerdict::kFailed, "failed"},
    {LinkVerdict::kInconsistent, "inconsistent"},
    {LinkVerdict::kPending, "pending"},
}};

}  // namespace

const char* to_string(LinkVerdict verdict) {
  for (const auto& [v, name] : kNames)
    if (v == verdict) return name;
  return "?";
}

LinkVerdict link_verdict_from_string(const std::string& name) {
  for (const auto& [v, n] : kNames)
    if (name == n) return v;
  fail(ErrorCode::kInvalidArgument, "unknown link verdict '" + name + "'");
}

}  // namespace k4reg
