// Which files a request may reference: existing regular files under the configured data roots.
// Every path is resolved (".." and symlinks) before the containment check, so neither "../x", nor an
// absolute path elsewhere, nor a symlink inside a root that leads out of it gets through. The file is opened
// later, after the queue wait: open() checks again where the path leads then, so a symlink swapped in meanwhile
// cannot lead out of the roots either, and a FIFO swapped in is refused instead of blocking the worker.
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

  // A descriptor for reading `resolved` (what resolve() returned), where the path leads now: beneath its root
  // (openat2 RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS; on kernels without openat2, through no symlink at all) and
  // a regular file, opened without blocking on a FIFO. The caller closes it. Throws k4reg::Error naming
  // `requested`: kPermissionDenied when the path now leads out of its root, kNotFound when it is gone,
  // kInvalidArgument when it is no regular file.
  int open(const std::string& resolved, const std::string& requested) const;

 private:
  // The root `canonical` lies in, or null.
  const std::filesystem::path* root_of(const std::filesystem::path& canonical) const;

  std::vector<std::filesystem::path> roots_;  // canonical
};

}  // namespace k4reg::service
