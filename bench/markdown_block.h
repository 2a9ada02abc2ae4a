// Generated blocks of bench/RESULTS.md: each benchmark owns the text between "<!-- name:begin -->" and
// "<!-- name:end -->" and rewrites only that, so hand-written text around it survives reruns.
#pragma once

#include <string>

namespace k4reg::bench {

// Replaces the text between "<!-- name:begin -->" and "<!-- name:end -->" in file (appending the block
// when the markers are missing, creating the file when needed). Throws std::runtime_error when the file
// cannot be written.
void replace_block(const std::string& file, const std::string& name, const std::string& content);

// How a link in the markdown file reaches dir (both as given on the command line, relative or absolute).
std::string path_from_markdown(const std::string& markdown_file, const std::string& dir);

}  // namespace k4reg::bench
