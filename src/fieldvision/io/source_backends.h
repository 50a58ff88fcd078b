// The frame-source backends behind OpenFrameSource (frame_source.h), one per file; internal to
// io. Each opens its spec or throws fv::Error naming it.
#pragma once

#include <memory>
#include <string>

#include "fieldvision/io/frame_source.h"

namespace fv::io::backend {

// A video file OpenCV reads or a printf image pattern (file_source.cc).
std::unique_ptr<FrameSource> OpenFile(const std::string& path, const FrameSourceOptions& options);
// A glob (dir/*.png) or a folder of images, in name order (image_list_source.cc).
std::unique_ptr<FrameSource> OpenImageList(const std::string& spec,
                                           const FrameSourceOptions& options);
// `source` delivered at its frame rate from options.start_at_s (paced_source.cc).
std::unique_ptr<FrameSource> Paced(std::unique_ptr<FrameSource> source,
                                   const FrameSourceOptions& options);
// "v4l2:/dev/videoN" or "camera:N" (v4l2_source.cc).
std::unique_ptr<FrameSource> OpenV4l2(const std::string& spec, const FrameSourceOptions& options);
// "gst:PIPELINE" or "rtsp://..." (gstreamer_source.cc); nullptr-free: throws when OpenCV has no
// GStreamer backend.
std::unique_ptr<FrameSource> OpenGStreamer(const std::string& spec,
                                           const FrameSourceOptions& options);
bool HaveGStreamer();
// "aravis:[DEVICE-ID]" (aravis_source.cc); throws when built without Aravis.
std::unique_ptr<FrameSource> OpenAravis(const std::string& spec, const FrameSourceOptions& options);
bool HaveAravis();
// "synth:PRESET_OR_JSON?camera=NAME&seed=N&width=W&height=H&frames=N" (synth_source.cc).
std::unique_ptr<FrameSource> OpenSynth(const std::string& spec, const FrameSourceOptions& options);

// Seconds on the system clock of a CLOCK_MONOTONIC time in seconds (V4L2 buffer timestamps).
double SystemFromMonotonic(double monotonic_s);

}  // namespace fv::io::backend
