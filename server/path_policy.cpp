#include "path_policy.h"

#include <algorithm>

#include "k4reg/util/error.h"

namespace k4reg::service {
namespace fs = std::filesystem;

PathPolicy::PathPolicy(const std::vector<std::string>& roots) {
  for (const std::string& root : roots) {
    std::error_code ec;
    const fs::path canonical = fs::canonical(root, ec);
    if (ec || !fs::is_directory(canonical))
      fail(ErrorCode::kInvalidArgument, "data root " + root + " is not an existing directory");
    roots_.push_back(canonical);
  }
}

bool PathPolicy::inside_a_root(const fs::path& canonical) const {
  return std::any_of(roots_.begin(), roots_.end(), [&](const fs::path& root) {
    // Component-wise prefix: "/data/scans2" is not inside "/data/scans".
    return std::mismatch(root.begin(), root.end(), canonical.begin(), canonical.end()).first == root.end();
  });
}

std::string PathPolicy::resolve(const std::string& requested) const {
  if (requested.empty()) fail(ErrorCode::kInvalidArgument, "empty path");
  if (requested.find('\0') != std::string::npos) fail(ErrorCode::kInvalidArgument, "path contains a NUL byte");
  const fs::path path(requested);
  std::vector<fs::path> candidates;
  if (path.is_absolute())
    candidates.push_back(path);
  else
    for (const fs::path& root : roots_) candidates.push_back(root / path);

  bool missing_inside = false;
  for (const fs::path& candidate : candidates) {
    std::error_code ec;
    // Resolves symlinks along the existing part of the path and normalises the rest lexically.
    const fs::path resolved = fs::weakly_canonical(candidate, ec);
    if (ec || !inside_a_root(resolved)) continue;
    const fs::file_status status = fs::status(resolved, ec);
    if (ec || !fs::exists(status)) {
      missing_inside = true;
      continue;
    }
    if (!fs::is_regular_file(status)) fail(ErrorCode::kInvalidArgument, requested + ": not a regular file");
    return resolved.string();
  }
  if (missing_inside) fail(ErrorCode::kNotFound, requested + ": no such file under the data roots");
  fail(ErrorCode::kPermissionDenied, requested + ": outside the server's data roots");
}

}  // namespace k4reg::service
