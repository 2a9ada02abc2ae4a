#include "http_upload.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "http_json.h"
#include "k4reg/util/error.h"

namespace k4reg::service {
namespace {

constexpr std::array<const char*, 2> kRoles{"source", "target"};

const google::protobuf::FieldDescriptor* parameter_field(const std::string& name) {
  const google::protobuf::FieldDescriptor* field = v1::RegistrationParams::descriptor()->FindFieldByName(name);
  if (!field)
    fail(ErrorCode::kInvalidArgument,
         fmt::format("unknown form field '{}': expected source, target or a RegistrationParams field "
                     "(min_scale_m, overlap, seed, ...)",
                     name));
  return field;
}

// Form fields are text; the JSON mapping wants true/false as JSON booleans and accepts numbers and enum
// names as strings, so the protobuf parser does every check and names the field in its message.
v1::RegistrationParams params_from_fields(const std::map<std::string, std::string>& fields) {
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [name, value] : fields) {
    const auto type = parameter_field(name)->cpp_type();
    if (type == google::protobuf::FieldDescriptor::CPPTYPE_BOOL && (value == "true" || value == "false"))
      json[name] = value == "true";
    else if (type == google::protobuf::FieldDescriptor::CPPTYPE_ENUM && !value.empty() &&
             value.find_first_not_of("0123456789") == std::string::npos)
      json[name] = std::stoi(value.substr(0, 9));
    else
      json[name] = value;
  }
  v1::RegistrationParams params;
  from_json(json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), params);
  return params;
}

}  // namespace

UploadForm read_upload_form(RequestBody& body, const ServiceContext& service) {
  UploadForm form;
  std::array<bool, 2> seen{};
  std::array<std::string, 2> paths;
  std::map<std::string, std::string> fields;
  SpoolFile* file = nullptr;       // the part being received, if it is a file
  std::string* text = nullptr;     // the part being received, if it is a path or a parameter
  std::string part_name;

  const auto begin = [&](const httplib::MultipartFormData& part) {
    part_name = part.name;
    file = nullptr;
    text = nullptr;
    const auto role = std::find(kRoles.begin(), kRoles.end(), part.name) - kRoles.begin();
    if (role == 2) {
      parameter_field(part.name);
      const auto [field, inserted] = fields.try_emplace(part.name);
      if (!inserted) fail(ErrorCode::kInvalidArgument, "form field '" + part.name + "' given twice");
      text = &field->second;
      return;
    }
    if (seen[role]) fail(ErrorCode::kInvalidArgument, "form part '" + part.name + "' given twice");
    seen[role] = true;
    if (part.filename.empty()) {
      text = &paths[role];
      return;
    }
    form.files[role] = service.spool.create(part.filename);
    form.clouds[role] = {part.filename, form.files[role]->path(), {}};
    file = form.files[role].get();
  };

  const auto append = [&](std::string_view bytes) {
    if (file) {
      if (file->size() + bytes.size() > service.max_upload_bytes)
        fail(ErrorCode::kResourceExhausted,
             fmt::format("{}: more than the upload limit of {} MiB (--max-upload-mb)", part_name,
                         service.max_upload_bytes >> 20));
      file->append(bytes);
    } else if (text) {
      if (text->size() + bytes.size() > kMaxFormFieldBytes)
        fail(ErrorCode::kResourceExhausted,
             fmt::format("form field '{}' longer than {} bytes", part_name, kMaxFormFieldBytes));
      text->append(bytes);
    }
  };

  body.read_multipart(begin, append);
  for (std::size_t role = 0; role < 2; ++role) {
    if (!seen[role])
      fail(ErrorCode::kInvalidArgument,
           fmt::format("missing form part '{}' (a file, or a path under the data roots)", kRoles[role]));
    if (form.files[role])
      form.files[role]->close();
    else
      form.clouds[role] = service.referenced_cloud(paths[role]);
  }
  form.params = params_from_fields(fields);
  return form;
}

}  // namespace k4reg::service
