#include "http/http_upload.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>

#include "http/http_json.h"
#include "k4reg/project/candidate_pairs.h"
#include "pair_selection.h"
#include "k4reg/util/error.h"

namespace k4reg::service {
namespace {

// The parameter named `name`: where it goes in the request, and its field there.
struct FormField {
  bool project_level = false;  // a ProjectParams field (reference, pairs, partners) rather than a RegistrationParams one
  const google::protobuf::FieldDescriptor* field = nullptr;
};

FormField form_field(const std::string& name, FormKind kind) {
  if (kind == FormKind::kProject && (name == "reference" || name == "pairs" || name == "partners"))
    return {true, v1::ProjectParams::descriptor()->FindFieldByName(name)};
  const google::protobuf::FieldDescriptor* field = v1::RegistrationParams::descriptor()->FindFieldByName(name);
  if (!field)
    fail(ErrorCode::kInvalidArgument,
         fmt::format("unknown form field '{}': expected {}, preview_points{} or a RegistrationParams field "
                     "(min_scale_m, overlap, seed, ...)",
                     name, kind == FormKind::kPair ? "source, target" : "scans", kind == FormKind::kPair ? "" : ", reference, pairs, partners"));
  return {false, field};
}

// A form field's text as the JSON mapping wants it: true/false as JSON booleans, enum numbers as numbers, the
// pair selections also by their short names; numbers and enum names stay strings, which the mapping accepts.
nlohmann::json json_value(const google::protobuf::FieldDescriptor& field, const std::string& value) {
  using google::protobuf::FieldDescriptor;
  if (field.cpp_type() == FieldDescriptor::CPPTYPE_BOOL && (value == "true" || value == "false")) return value == "true";
  if (field.cpp_type() == FieldDescriptor::CPPTYPE_ENUM) {
    if (!value.empty() && value.find_first_not_of("0123456789") == std::string::npos) return std::stoi(value.substr(0, 9));
    if (field.enum_type() == v1::PairSelection_descriptor())
      if (const std::optional<PairSelection> named = pair_selection_named(value))
        return v1::PairSelection_Name(api::pair_selection_to_proto(*named));
  }
  return value;
}

// The parameters as a ProjectParams (the protobuf parser does every check and names the field).
v1::ProjectParams params_from_fields(const std::map<std::string, std::string>& fields, FormKind kind) {
  nlohmann::json json = {{"pairwise", nlohmann::json::object()}};
  for (const auto& [name, value] : fields) {
    const FormField field = form_field(name, kind);
    (field.project_level ? json : json["pairwise"])[name] = json_value(*field.field, value);
  }
  v1::ProjectParams params;
  from_json(json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), params);
  return params;
}

std::uint32_t preview_points_from_field(const std::string& value) {
  if (value.empty() || value.size() > 9 || value.find_first_not_of("0123456789") != std::string::npos)
    fail(ErrorCode::kInvalidArgument, "form field 'preview_points' must be a whole number (0 = no preview)");
  return static_cast<std::uint32_t>(std::stoul(value));
}

}  // namespace

UploadForm read_upload_form(RequestBody& body, const ServiceContext& service, FormKind kind) {
  const std::vector<std::string> roles = kind == FormKind::kPair ? std::vector<std::string>{"source", "target"}
                                                                 : std::vector<std::string>{"scans"};
  UploadForm form;
  std::vector<std::string> cloud_roles;  // per cloud part, in order
  std::vector<std::string> paths;        // per cloud part: the path, for a part without a file name
  std::map<std::string, std::string> fields;
  SpoolFile* file = nullptr;    // the part being received, if it is a file
  std::string* text = nullptr;  // the part being received, if it is a path or a parameter
  std::string part_name;
  std::size_t parts = 0;

  const auto begin = [&](const httplib::MultipartFormData& part) {
    if (++parts > kMaxFormParts)
      fail(ErrorCode::kResourceExhausted, fmt::format("more than {} form parts (the HTTP API's limit)", kMaxFormParts));
    part_name = part.name;
    file = nullptr;
    text = nullptr;
    if (std::find(roles.begin(), roles.end(), part.name) == roles.end()) {
      if (part.name != "preview_points") form_field(part.name, kind);
      const auto [field, inserted] = fields.try_emplace(part.name);
      if (!inserted) fail(ErrorCode::kInvalidArgument, "form field '" + part.name + "' given twice");
      text = &field->second;
      return;
    }
    if (kind == FormKind::kPair && std::find(cloud_roles.begin(), cloud_roles.end(), part.name) != cloud_roles.end())
      fail(ErrorCode::kInvalidArgument, "form part '" + part.name + "' given twice");
    service.limits.check_project_scans(cloud_roles.size() + 1);  // before its spool file
    cloud_roles.push_back(part.name);
    paths.emplace_back();
    form.clouds.emplace_back();
    if (part.filename.empty()) {
      form.files.emplace_back();
      text = &paths.back();
      return;
    }
    form.files.push_back(service.spool.create(part.filename));
    form.clouds.back() = {part.filename, form.files.back()->path(), {}};
    file = form.files.back().get();
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
  for (const std::string& role : roles)
    if (std::find(cloud_roles.begin(), cloud_roles.end(), role) == cloud_roles.end())
      fail(ErrorCode::kInvalidArgument,
           fmt::format("missing form part '{}' (a file, or a path under the data roots)", role));
  if (kind == FormKind::kPair && cloud_roles.front() != "source") {  // the worker takes source first
    std::swap(form.clouds[0], form.clouds[1]);
    std::swap(form.files[0], form.files[1]);
    std::swap(paths[0], paths[1]);
  }
  for (std::size_t i = 0; i < form.clouds.size(); ++i) {
    if (form.files[i])
      form.files[i]->close();
    else
      form.clouds[i] = service.referenced_cloud(paths[i]);
  }
  if (const auto preview = fields.find("preview_points"); preview != fields.end()) {
    form.preview_points = preview_points_from_field(preview->second);
    fields.erase(preview);
  }
  form.params = params_from_fields(fields, kind);
  return form;
}

}  // namespace k4reg::service
