// OpenCV's image codecs (imgcodecs) and video I/O (videoio), loaded when first used. Linked into
// the program, they and what they link (GDAL, FFmpeg, GStreamer: about 250 shared libraries)
// are loaded and relocated before main() of every command, 0.12 s whether it reads an image or
// not. Here they sit in a plugin (libfieldvision_codecs.so, plugin.cc) that dlopen() loads the
// first time one of these functions needs it; each behaves as the OpenCV function it names.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

namespace fv::codecs {

// cv::imread: an empty image when the file is missing or does not decode (the decoders' own
// messages on stderr are dropped: the caller reports the failure).
cv::Mat ImRead(const std::string& path, int flags = cv::IMREAD_COLOR);
// cv::imwrite (the format from the extension): false when it cannot be written.
bool ImWrite(const std::string& path, cv::InputArray image, const std::vector<int>& params = {});
// cv::imdecode: an empty image when `buffer` does not decode (quiet, as ImRead).
cv::Mat ImDecode(cv::InputArray buffer, int flags = cv::IMREAD_COLOR);
// cv::imencode into `buffer`; false when the format `ext` (".jpg", ".png") cannot encode it.
bool ImEncode(const std::string& ext, cv::InputArray image, std::vector<uchar>* buffer,
              const std::vector<int>& params = {});

// An unopened capture or writer made by the plugin. Use its virtual members only (open,
// isOpened, read, grab, write, get, set, release): the others are not linked into the program.
std::unique_ptr<cv::VideoCapture> NewVideoCapture();
std::unique_ptr<cv::VideoWriter> NewVideoWriter();
// cv::VideoWriter::open with a backend (cv::CAP_FFMPEG, cv::CAP_OPENCV_MJPEG, cv::CAP_ANY).
bool OpenVideoWriter(cv::VideoWriter* writer, const std::string& path, int api, int fourcc,
                     double fps, cv::Size size, bool is_color = true);
// cv::VideoCapture::getBackendName ("" when not opened) and cv::videoio_registry::hasBackend.
std::string BackendName(const cv::VideoCapture& capture);
bool HasVideoBackend(int api);

// cv::VideoWriter::fourcc.
constexpr int FourCc(char c1, char c2, char c3, char c4) {
  return (c1 & 255) | ((c2 & 255) << 8) | ((c3 & 255) << 16) | ((c4 & 255) << 24);
}

// Damaged data FFmpeg's decoders reported since the first call (each call after a capture opened
// keeps FFmpeg's log counted: OpenCV sets its own callback at its first open); -1 when the plugin
// was built without libavutil. 0 without loading the plugin when it is not loaded.
long long DecoderProblems();

// Whether the log of the libraries the plugin brings in (GLib / GStreamer) reaches stderr
// (default: not; --verbose turns it on).
void SetLibraryLogs(bool shown);

// Loads the plugin now (e.g. on another thread while the program does other work); throws
// fv::Error naming the plugin when it cannot be loaded. Every function above calls it.
void Load();

}  // namespace fv::codecs
