// The k4reg command line: local alignment, and (with the service) remote registration, health and load.
// Exit codes: 0 success, 1 failure (one line "k4reg: ..." on stderr), 2 usage error.
#include <CLI/CLI.hpp>
#include <iostream>

#include "commands/align_command.h"
#include "commands/align_project_command.h"
#include "commands/command_error.h"
#include "k4reg/util/error.h"
#ifdef K4REG_REMOTE_COMMANDS
#include "commands/health_command.h"
#include "commands/load_command.h"
#include "commands/register_command.h"
#include "commands/register_project_command.h"
#endif

int main(int argc, char** argv) {
  CLI::App app{"k4reg: markerless registration of laser scans (K-4PCS)"};
  app.require_subcommand(1);
  k4reg::cli::add_align_command(app);
  k4reg::cli::add_align_project_command(app);
#ifdef K4REG_REMOTE_COMMANDS
  k4reg::cli::add_register_command(app);
  k4reg::cli::add_register_project_command(app);
  k4reg::cli::add_health_command(app);
  k4reg::cli::add_load_command(app);
#endif
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // a command's verdict (e.g. health: not serving), already reported
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;  // --help is a ParseError too
  } catch (const k4reg::cli::CommandError& e) {
    std::cerr << "k4reg: " << e.what() << "\n";
    return 1;
  } catch (const k4reg::Error& e) {
    std::cerr << "k4reg: " << k4reg::to_string(e.code()) << ": " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "k4reg: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
