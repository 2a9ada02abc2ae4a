#include "markdown_block.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace k4reg::bench {

void replace_block(const std::string& file, const std::string& name, const std::string& content) {
  const std::string begin = "<!-- " + name + ":begin -->", end = "<!-- " + name + ":end -->";
  std::string text;
  if (std::ifstream in(file); in) text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  const std::string block = begin + "\n" + content + (content.ends_with("\n") ? "" : "\n") + end;
  const std::size_t b = text.find(begin), e = text.find(end);
  if (b != std::string::npos && e != std::string::npos && e > b)
    text.replace(b, e + end.size() - b, block);
  else
    text.append(text.empty() || text.ends_with("\n") ? "\n" : "\n\n").append(block).append("\n");
  std::ofstream out(file);
  if (!out) throw std::runtime_error("cannot write " + file);
  out << text;
}

std::string path_from_markdown(const std::string& markdown_file, const std::string& dir) {
  namespace fs = std::filesystem;
  return fs::relative(fs::absolute(dir), fs::absolute(markdown_file).parent_path()).string();
}

}  // namespace k4reg::bench
