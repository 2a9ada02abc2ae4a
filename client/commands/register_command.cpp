#include "commands/register_command.h"

#include <fmt/format.h>
#include <unistd.h>

#include <iostream>
#include <memory>

#include "remote/channel.h"
#include "k4reg/io/matrix_file.h"
#include "reports/progress_bar.h"
#include "reports/qa_report.h"
#include "messages_to_core.h"
#include "remote/proto_mapping.h"
#include "commands/registration_flags.h"
#include "remote/remote_registration.h"
#include "reports/result_report.h"
#include "remote/server_timings.h"

namespace k4reg::cli {
namespace {

struct RegisterOptions {
  std::string source, target, out, request_id;
  bool by_reference = false, json = false, progress = false;
  double deadline_s = 0;
  int retries = 2;
  ConnectionOptions connection;
  RegistrationParams params;
  RegistrationFlags flags{};
  ReportFlags report;
};

void print_server_table(std::ostream& out, const v1::RegisterResponse& response) {
  const v1::ServerTimings& t = response.timings();
  out << fmt::format("{:<22}k4reg {} ({})\n", "server", response.server().version(), response.server().server_id());
  out << fmt::format("{:<22}{}\n", "request id", response.request_id());
  out << fmt::format(
      "{:<22}queue {:.3f} s, upload {:.3f} s, load {:.3f} s, registration {:.3f} s, overhead {:.1f} ms\n",
      "server timings", t.queue_wait_s(), t.upload_s(), t.load_s(), t.registration_s(), 1000.0 * server_overhead_s(t));
}

void run_register(const RegisterOptions& o) {
  const RemoteRegistration job{o.source, o.target, o.by_reference, params_to_proto(o.params, o.flags),
                               o.report.wanted() ? static_cast<std::uint32_t>(o.report.preview_points) : 0u};
  const CallPolicy policy{o.deadline_s, o.retries, o.request_id.empty() ? new_request_id() : o.request_id};
  v1::RegisterResponse response;
  {
    ProgressBar progress(std::cerr,
                         o.progress || isatty(STDERR_FILENO) ? ProgressBar::Style::kBar : ProgressBar::Style::kLines);
    response = register_remote(make_channel(o.connection), o.connection, job, policy, progress);
  }
  const RegistrationResult result = api::result_from_proto(response.result());
  if (!o.out.empty()) write_matrix4(o.out, result.transform);
  // align's layout, plus where and how the job ran.
  nlohmann::json json = result_to_json(result);
  json["request_id"] = response.request_id();
  json["server"] = {{"version", response.server().version()}, {"server_id", response.server().server_id()}};
  json["server_timings"] = server_timings_to_json(response.timings());
  if (o.report.wanted()) {
    const CloudPreview preview = api::preview_from_proto(response.preview());
    write_pair_report(o.report, "k4reg register", o.source, o.target, o.params, json, &preview);
  }
  if (o.json) {
    std::cout << json.dump(2) << "\n";
  } else {
    print_result_table(std::cout, result);
    print_server_table(std::cout, response);
  }
}

}  // namespace

void add_register_command(CLI::App& app) {
  auto options = std::make_shared<RegisterOptions>();
  CLI::App* command = app.add_subcommand(
      "register",
      "register SOURCE onto TARGET on a k4reg server: local files are uploaded, or with --ref named on the server.\n"
      "Parameter flags not given are not sent, so the server's defaults apply (the same as align's, except\n"
      "--threads: the server's --job-threads).");
  command->add_option("SOURCE", options->source, "source scan: a local file, or with --ref a path on the server")
      ->required();
  command->add_option("TARGET", options->target, "target scan")->required();
  add_connection_flags(*command, options->connection);
  options->flags = add_registration_flags(*command, options->params);
  command->add_flag("--ref", options->by_reference,
                    "SOURCE and TARGET are paths under the server's --data-root, nothing is uploaded");
  command->add_flag("--json", options->json, "print the result as JSON (align's layout plus server and timings)");
  command->add_option("--out", options->out, "write the 4x4 source->target matrix to this file");
  command->add_option("--deadline", options->deadline_s, "give up after this many seconds, retries included; 0 = never")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  command->add_option("--retries", options->retries, "attempts after UNAVAILABLE, 1 s, 2 s, 4 s ... apart")
      ->capture_default_str()
      ->check(CLI::Range(0, 100));
  command->add_option("--request-id", options->request_id, "x-request-id of the call (default: a new UUID)");
  command->add_flag("--progress", options->progress, "draw the progress bar even when stderr is not a terminal");
  add_report_flags(*command, options->report);
  command->callback([options] { run_register(*options); });
}

}  // namespace k4reg::cli
