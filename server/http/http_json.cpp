#include "http/http_json.h"

#include <google/protobuf/util/json_util.h>

#include <nlohmann/json.hpp>

#include "k4reg/util/error.h"
#include "status_name.h"

namespace k4reg::service {

std::string to_json(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  std::string json;
  const auto status = google::protobuf::util::MessageToJsonString(message, &json, options);
  if (!status.ok()) fail(ErrorCode::kInternal, "cannot write JSON: " + status.ToString());
  return json;
}

void from_json(std::string_view json, google::protobuf::Message& message) {
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  const auto status = google::protobuf::util::JsonStringToMessage(json, &message, options);
  if (!status.ok())
    fail(ErrorCode::kInvalidArgument,
         "invalid JSON for " + message.GetDescriptor()->name() + ": " + std::string(status.message()));
}

std::string error_json(const grpc::Status& status, const std::string& request_id) {
  const nlohmann::json body{
      {"code", status_code_name(status.error_code())}, {"message", status.error_message()}, {"request_id", request_id}};
  // Messages may quote client input that is not UTF-8: replace rather than throw.
  return body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace k4reg::service
