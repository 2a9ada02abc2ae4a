// What `k4reg align-project` (local) and `k4reg register-project` (remote) share on the command line: the
// project flags, the pair list, and the line each finished pair prints.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "k4reg/project/project_registration.h"

namespace k4reg::cli {

struct ProjectFlags {
  std::string pairs = "auto";  // auto, all, sequence, screened or a file of index pairs
  bool json = false;
  bool quiet = false;  // no line per finished pair on stderr
  std::string out_dir;
  CLI::Option* reference = nullptr;  // count() = given
  CLI::Option* partners = nullptr;
};

// --reference, --pairs, --partners, --json, --quiet, --out-dir.
void add_project_flags(CLI::App& command, ProjectFlags& flags, ProjectParams& params);

// --pairs into the parameters (reads the file of a list). Throws k4reg::Error for a bad list file.
void apply_pairs(const ProjectFlags& flags, ProjectParams& params);

// "pair 3/10: scan 0 -> 4: 1.2 s" (and why it failed, if it did).
std::string pair_line(std::size_t index, std::size_t pairs, std::size_t source, std::size_t target, double seconds,
                      const std::string& error);

}  // namespace k4reg::cli
