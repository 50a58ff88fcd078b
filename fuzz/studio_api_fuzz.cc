// libFuzzer harness: the studio's HTTP API (web/studio_api.h) on a small working folder. The first
// byte picks an endpoint (or, past the list, a free path); the first line is the query
// (k=v&k=v), the rest the body. Every answer must be a JSON body with a 2xx or 4xx status and a
// one-line error: a 5xx ("internal error", an exception that is not an fv::Error) is a finding.
#include <nlohmann/json.hpp>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/web/studio_api.h"
#include "fuzz/fuzz_common.h"

namespace {

namespace fs = std::filesystem;

// The working folder, made again for every input (POST requests write files).
fs::path MakeWorkspace() {
  const fs::path ws = fv::fuzz::ScratchDir() / "ws";
  std::error_code ec;
  fs::remove_all(ws, ec);
  fs::create_directories(ws / "out");
  fv::camera::WriteCameraYaml(fv::camera::Camera::FromFov(640, 480, 60),
                              (ws / "cam.yaml").string());
  fv::fuzz::WriteInput("time_s,frame,x_m,y_m,z_m,cameras,err_px\n0,0,1,2,0.11,2,0.5\n",
                       "ws/BALL.csv");
  fv::fuzz::WriteInput("[{\"name\": \"box\", \"polygon\": [[0, 0], [1, 0], [1, 1]]}]",
                       "ws/zones.json");
  return ws;
}

std::map<std::string, std::string> ParseQuery(std::string_view q) {
  std::map<std::string, std::string> params;
  while (!q.empty()) {
    const size_t amp = q.find('&');
    const std::string_view kv = q.substr(0, amp);
    const size_t eq = kv.find('=');
    params[std::string(kv.substr(0, eq))] =
        eq == std::string_view::npos ? "" : std::string(kv.substr(eq + 1));
    if (amp == std::string_view::npos) break;
    q.remove_prefix(amp + 1);
  }
  return params;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  std::string_view rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  const auto& endpoints = fv::web::StudioApi::Endpoints();
  fv::web::ApiRequest request;
  const size_t pick = data[0];
  const size_t newline = rest.find('\n');
  std::string_view query = rest.substr(0, newline);
  rest = newline == std::string_view::npos ? std::string_view() : rest.substr(newline + 1);
  if (pick < endpoints.size()) {
    if (endpoints[pick].path == "/api/events" || endpoints[pick].path == "/api/jobs") return 0;
    request.method = endpoints[pick].method;
    request.path = endpoints[pick].path;
  } else {
    request.method = pick % 2 ? "POST" : "GET";
    request.path = std::string(query.substr(0, query.find('?')));
    query = query.find('?') == std::string_view::npos ? "" : query.substr(query.find('?') + 1);
  }
  request.params = ParseQuery(query);
  request.body = std::string(rest);
  static const fs::path ws = MakeWorkspace();
  MakeWorkspace();
  const fv::web::StudioApi api(fv::web::Workspace(ws), nullptr);
  const fv::web::ApiResponse response = api.Handle(request);
  if (response.status >= 500) {
    std::fprintf(stderr, "fuzz: %s %s: status %d: %s\n", request.method.c_str(),
                 request.path.c_str(), response.status, response.body.c_str());
    std::abort();
  }
  if (response.content_type == "application/json") {
    const auto j = nlohmann::json::parse(response.body, nullptr, false);
    if (j.is_discarded()) {
      std::fprintf(stderr, "fuzz: %s: body is not JSON\n", request.path.c_str());
      std::abort();
    }
    if (response.status >= 400) {
      const std::string error = j.value("error", std::string());
      fv::fuzz::CheckOneLine(error.c_str());
      if (error.empty()) std::abort();
    }
  }
  return 0;
}
