#include "commands/load_command.h"

#include <filesystem>
#include <iostream>
#include <memory>
#include <utility>
#include <vector>

#include "remote/channel.h"
#include "commands/command_error.h"
#include "reports/load_report.h"
#include "remote/load_runner.h"
#include "remote/local_file.h"
#include "remote/proto_mapping.h"
#include "commands/registration_flags.h"

namespace k4reg::cli {
namespace {

struct LoadOptions {
  ConnectionOptions connection;
  LoadPlan plan;
  std::vector<std::pair<std::string, std::string>> pairs;
  bool upload = false, json = false;
  RegistrationParams params;
  RegistrationFlags flags{};
  CLI::Option* duration_flag = nullptr;  // given: the run is bounded by time, not by a count
};

void set_cloud(v1::CloudInput& cloud, const std::string& file, bool upload) {
  if (!upload) {
    cloud.set_path(file);
    return;
  }
  // Read once, sent inline with every call: the load test measures the service, not the client's disk.
  cloud.mutable_inline_cloud()->set_data(read_local_file(file));
  cloud.mutable_inline_cloud()->set_file_name(std::filesystem::path(file).filename().string());
}

void run_load_command(LoadOptions& o) {
  if (o.duration_flag->count() > 0) o.plan.total = 0;
  const v1::RegistrationParams params = params_to_proto(o.params, o.flags);
  for (const auto& [source, target] : o.pairs) {
    v1::RegisterRequest& request = o.plan.requests.emplace_back();
    set_cloud(*request.mutable_source(), source, o.upload);
    set_cloud(*request.mutable_target(), target, o.upload);
    *request.mutable_params() = params;
  }
  const LoadOutcome outcome = run_load(make_channel(o.connection), o.connection, o.plan);
  const LoadSummary summary = summarize_load(outcome);
  if (o.json)
    std::cout << load_summary_to_json(o.plan, summary).dump(2) << "\n";
  else
    print_load_summary(std::cout, o.plan, summary);
  // Refusals under load are results; a run where nothing got through (wrong address, token, path) is an error.
  if (summary.status_counts.count("OK") == 0) throw CommandError(outcome.first_failure);
}

}  // namespace

void add_load_command(CLI::App& app) {
  auto options = std::make_shared<LoadOptions>();
  LoadPlan& plan = options->plan;
  CLI::App* command = app.add_subcommand(
      "load",
      "load-test a k4reg server with unary Register calls: closed loop (--concurrency callers) or open loop\n"
      "(--rate calls per second); stops after --requests calls or --duration seconds");
  add_connection_flags(*command, options->connection);
  command
      ->add_option("--pair", options->pairs,
                   "SOURCE TARGET paths on the server (local files with --upload); repeat for round robin")
      ->required();
  command->add_flag(
      "--upload", options->upload,
      "read the pairs' local files once and send them inline with every call (server limit: --max-inline-mb)");
  auto* concurrency = command->add_option("--concurrency", plan.concurrency, "closed loop: calls in flight")
                          ->capture_default_str()
                          ->check(CLI::Range(1, 10000));
  command->add_option("--rate", plan.rate, "open loop: start this many calls per second, whatever the completions")
      ->check(CLI::PositiveNumber)
      ->excludes(concurrency);
  auto* requests = command->add_option("--requests", plan.total, "calls to send")
                       ->capture_default_str()
                       ->check(CLI::Range(std::size_t{1}, std::size_t{10000000}));
  options->duration_flag =
      command->add_option("--duration", plan.duration_s, "send calls for this many seconds instead of --requests")
          ->check(CLI::PositiveNumber)
          ->excludes(requests);
  command->add_option("--deadline", plan.deadline_s, "seconds each call may take")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  options->flags = add_registration_flags(*command, options->params);
  command->add_flag("--json", options->json, "print the report as JSON");
  command->callback([options] { run_load_command(*options); });
}

}  // namespace k4reg::cli
