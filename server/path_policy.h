// Which files a request may reference: existing regular files under the configured data roots.
// Every path is resolved (".." and symlinks) before the containment check, so neither "../x", nor an
// absolute path elsewhere, nor a symlink inside a root that leads out of it gets through.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace k4reg::service {

class PathPolicy {
 public:
  // Throws k4reg::Error(kInvalidArgument) if a root is not an existing directory (a configuration error).
  explicit PathPolicy(const std::vector<std::string>& roots);

  // The canonical path of `requested`: relative paths are tried against each root in order, absolute
  // ones must lie inside a root. Throws k4reg::Error: kPermissionDenied outside every root (also when
  // no root is configured), kNotFound if missing inside a root, kInvalidArgument if empty or not a
  // regular file. Messages name the path as requested, never the server's roots.
  std::string resolve(const std::string& requested) const;

 private:
  bool inside_a_root(const std::filesystem::path& canonical) const;

  std::vector<std::filesystem::path> roots_;  // canonical
};

}  // namespace k4reg::service
