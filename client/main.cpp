// The k4reg command line: local alignment, and (with the service) remote registration, health and load.
#include <CLI/CLI.hpp>
#include <iostream>

#include "align_command.h"
#include "k4reg/error.h"

int main(int argc, char** argv) {
  CLI::App app{"k4reg: markerless registration of laser scans (K-4PCS)"};
  app.require_subcommand(1);
  k4reg::cli::add_align_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const k4reg::Error& e) {
    std::cerr << "k4reg: " << k4reg::to_string(e.code()) << ": " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "k4reg: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
