#include "commands/register_project_command.h"

#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "pair_selection.h"
#include "remote/channel.h"
#include "commands/command_error.h"
#include "k4reg/v1/registration.grpc.pb.h"
#include "remote/local_file.h"
#include "commands/project_flags.h"
#include "remote/project_mapping.h"
#include "reports/project_report.h"
#include "reports/qa_report.h"
#include "messages_to_core.h"
#include "remote/proto_mapping.h"
#include "commands/registration_flags.h"
#include "remote/server_timings.h"
#include "reports/status_text.h"
#include "remote/upload_stream.h"

namespace k4reg::cli {
namespace {

struct RegisterProjectOptions {
  std::vector<std::string> scans;
  bool by_reference = false;
  double deadline_s = 0;
  std::string request_id;
  ConnectionOptions connection;
  ProjectParams params;
  RegistrationFlags registration{};
  ProjectFlags flags;
  ReportFlags report;
};

// The header names every scan: a path on the server (--ref) or a local file whose chunks follow.
v1::ProjectUploadHeader make_header(const RegisterProjectOptions& o, ProjectParams& params, std::vector<LocalFile>& uploads) {
  apply_pairs(o.flags, params);
  v1::ProjectUploadHeader header;
  for (const std::string& scan : o.scans) {
    v1::StreamCloud& cloud = *header.add_scans();
    if (o.by_reference) {
      cloud.set_path(scan);
    } else {
      uploads.push_back(describe_local_file(scan));  // every file checked before connecting: a typo costs no upload
      *cloud.mutable_upload() = uploads.back().description;
    }
  }
  v1::ProjectParams& p = *header.mutable_params();
  *p.mutable_pairwise() = params_to_proto(params.pairwise, o.registration);
  if (o.flags.reference->count() > 0) p.set_reference(static_cast<std::uint32_t>(params.reference));
  p.set_pairs(api::pair_selection_to_proto(params.pairs));
  if (o.flags.partners->count() > 0) p.set_partners(static_cast<std::uint32_t>(params.partners));
  for (const auto& [first, second] : params.pair_list) {
    v1::ScanPair& pair = *p.add_pair_list();
    pair.set_first(static_cast<std::uint32_t>(first));
    pair.set_second(static_cast<std::uint32_t>(second));
  }
  return header;
}

void run_register_project(const RegisterProjectOptions& o) {
  ProjectParams params = o.params;
  std::vector<LocalFile> uploads;
  v1::RegisterProjectStreamRequest first;
  *first.mutable_header() = make_header(o, params, uploads);
  if (o.report.wanted()) first.mutable_header()->set_preview_points(static_cast<std::uint32_t>(o.report.preview_points));
  const auto channel = make_channel(o.connection);
  auto stub = v1::Registration::NewStub(channel);
  grpc::ClientContext context;
  add_call_metadata(context, o.connection, o.request_id.empty() ? new_request_id() : o.request_id);
  if (o.deadline_s > 0) context.set_deadline(deadline_after(o.deadline_s));
  auto stream = stub->RegisterProjectStream(&context);
  upload_files(
      *stream, context, first, uploads,
      [](std::size_t i, const std::string& piece) {
        v1::RegisterProjectStreamRequest chunk;
        chunk.mutable_chunk()->set_scan(static_cast<std::uint32_t>(i));
        chunk.mutable_chunk()->set_data(piece);
        return chunk;
      },
      [](std::uint64_t, std::uint64_t) {});
  // Queue position and each finished pair on stderr, as align-project prints them; stdout stays the result.
  v1::RegisterProjectResponse response;
  for (v1::RegisterProjectEvent event; stream->Read(&event);) {
    if (event.has_result()) response = event.result();
    if (o.flags.quiet) continue;
    if (event.has_queued()) std::cerr << fmt::format("queued: {} jobs ahead\n", event.queued().position());
    if (event.has_pair()) {
      const v1::PairEvent& pair = event.pair();
      std::cerr << pair_line(pair.index(), pair.pairs(), pair.source(), pair.target(), pair.seconds(), pair.error()) << "\n";
    }
  }
  if (const grpc::Status status = stream->Finish(); !status.ok())
    throw CommandError(describe_failure(status, *channel, o.connection.server));

  const ProjectResult result = project_result_from_proto(response.result());
  std::vector<ScanOrigin> origins;
  for (const std::string& scan : o.scans) origins.push_back({scan, -1});
  nlohmann::json json = project_to_json(result, origins, params);
  json["request_id"] = response.request_id();
  json["server"] = {{"version", response.server().version()}, {"server_id", response.server().server_id()}};
  json["server_timings"] = server_timings_to_json(response.timings());
  // Where the pairs ran: on the deployment's peers (k4reg-server --peers) or on the replica that answered.
  json["pairs_on_peers"] = response.pairs_on_peers();
  json["pairs_local"] = response.pairs_local();
  json["pair_retries"] = response.pair_retries();
  if (!o.flags.out_dir.empty()) write_project_dir(o.flags.out_dir, result, origins, json);
  if (o.report.wanted()) {
    const CloudPreview preview = api::preview_from_proto(response.preview());
    write_project_report(o.report, "k4reg register-project", o.scans, params, json, &preview);
  }
  if (o.flags.json)
    std::cout << json.dump(2) << "\n";
  else
    print_project_table(std::cout, result, origins);
}

}  // namespace

void add_register_project_command(CLI::App& app) {
  auto options = std::make_shared<RegisterProjectOptions>();
  CLI::App* command = app.add_subcommand(
      "register-project",
      "register a project of scans on a k4reg server (RegisterProjectStream): local files are uploaded in 1 MiB\n"
      "chunks (the server's --max-upload-mb bounds each), or with --ref named on the server. Parameter flags not\n"
      "given are not sent.");
  command->add_option("SCAN", options->scans, "the scans: local files, or with --ref paths on the server")->required();
  add_connection_flags(*command, options->connection);
  options->registration = add_registration_flags(*command, options->params.pairwise);
  add_project_flags(*command, options->flags, options->params);
  command->add_flag("--ref", options->by_reference, "the scans are paths under the server's --data-root, nothing is sent");
  command->add_option("--deadline", options->deadline_s, "give up after this many seconds; 0 = never")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  command->add_option("--request-id", options->request_id, "x-request-id of the call (default: a new UUID)");
  add_report_flags(*command, options->report);
  command->callback([options] { run_register_project(*options); });
}

}  // namespace k4reg::cli
