// The studio's JSON API over the fieldvision library: files of the working folder, fields,
// video frames, camera files, pose from clicked keypoints (calib/extrinsics.h) refined against
// the painted lines (calib/lines.h), intrinsics from board images (calib/intrinsics.h), ball colour
// learning and detection (detect/colour_learn.h, ball_detector.h), ball tracks, flights, player
// tracks, zones, jobs (jobs.h) and the live feed from a fusion node (live_feed.h). Every path is
// resolved inside the working folder (workspace.h); bad requests get a 4xx status and a one-line
// message ({"error": "..."}).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "fieldvision/web/events.h"
#include "fieldvision/web/jobs.h"
#include "fieldvision/web/live_feed.h"
#include "fieldvision/web/workspace.h"

namespace fv::web {

struct ApiRequest {
  std::string method;                         // "GET" or "POST"
  std::string path;                           // "/api/..."
  std::map<std::string, std::string> params;  // query parameters
  std::string body;                           // JSON for POST
};

struct ApiResponse {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
};

// One endpoint, as listed by GET /api/endpoints.
struct Endpoint {
  std::string method, path, summary;
};

class StudioApi {
 public:
  // `events` (optional) receives "saved" events; `jobs` (optional) runs jobs; `live` (optional)
  // subscribes to a fusion node; all must outlive the API.
  StudioApi(const Workspace& workspace, EventHub* events, JobRunner* jobs = nullptr,
            LiveFeed* live = nullptr);

  // Answers a request; never throws: 4xx/5xx responses carry {"error": one line}.
  ApiResponse Handle(const ApiRequest& request) const;
  static const std::vector<Endpoint>& Endpoints();
  const Workspace& workspace() const { return workspace_; }

 private:
  Workspace workspace_;
  EventHub* events_;
  JobRunner* jobs_;
  LiveFeed* live_;
};

}  // namespace fv::web
