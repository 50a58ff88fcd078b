#include "fieldvision/io/avi_mjpeg.h"

#include <algorithm>
#include <array>
#include <filesystem>

#include "fieldvision/codecs/codecs.h"

namespace fv::io {
namespace {

// A chunk id or list type as it reads from the file (codecs::FourCc's packing).
constexpr uint32_t FourCc(const char (&s)[5]) {
  return static_cast<uint32_t>(codecs::FourCc(s[0], s[1], s[2], s[3]));
}

uint32_t Le32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 |
         static_cast<uint32_t>(p[2]) << 16 | static_cast<uint32_t>(p[3]) << 24;
}

// The largest chunk taken as a frame: more is damage, not a JPEG.
constexpr uint32_t kMaxFrameBytes = 256u << 20;

bool IsMjpeg(uint32_t fourcc) {
  for (const uint32_t f : {FourCc("MJPG"), FourCc("mjpg"), FourCc("AVRn"), FourCc("LJPG"),
                           FourCc("JPGL"), FourCc("jpeg"), FourCc("JPEG"), FourCc("dmb1")}) {
    if (fourcc == f) return true;
  }
  return false;
}

// Reads a chunk header (id, size) at the stream's position.
bool ReadChunkHeader(std::ifstream& in, uint32_t* id, uint32_t* size) {
  uint8_t h[8];
  if (!in.read(reinterpret_cast<char*>(h), 8)) return false;
  *id = Le32(h);
  *size = Le32(h + 4);
  return true;
}

bool ReadFourCc(std::ifstream& in, uint32_t* v) {
  uint8_t b[4];
  if (!in.read(reinterpret_cast<char*>(b), 4)) return false;
  *v = Le32(b);
  return true;
}

}  // namespace

std::unique_ptr<AviMjpegReader> AviMjpegReader::Open(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || size < 12) return nullptr;
  std::unique_ptr<AviMjpegReader> r(new AviMjpegReader());
  r->in_.open(path, std::ios::binary);
  if (!r->in_) return nullptr;
  r->file_size_ = size;
  if (!r->ReadHeaders()) return nullptr;
  return r;
}

// RIFF 'AVI ' { LIST 'hdrl' { avih, LIST 'strl' {strh, strf, ...} ... }, ..., LIST 'movi' }:
// reads the headers and leaves the stream at the first chunk inside 'movi'.
bool AviMjpegReader::ReadHeaders() {
  uint32_t id = 0, size = 0, type = 0;
  if (!ReadChunkHeader(in_, &id, &size) || id != FourCc("RIFF")) return false;
  if (!ReadFourCc(in_, &type) || type != FourCc("AVI ")) return false;
  int stream = 0;
  while (ReadChunkHeader(in_, &id, &size)) {
    const uint64_t start = static_cast<uint64_t>(in_.tellg());
    const uint64_t end = start + size + (size & 1);
    if (id == FourCc("LIST")) {
      if (!ReadFourCc(in_, &type)) return false;
      if (type == FourCc("movi")) {
        if (fps_ <= 0) fps_ = avih_fps_;
        if (frames_ < 0) frames_ = avih_frames_;
        return have_video_;
      }
      if (type == FourCc("hdrl")) {
        // Walk into the header list: its chunks come next.
        while (static_cast<uint64_t>(in_.tellg()) + 8 <= end) {
          uint32_t cid = 0, csize = 0;
          if (!ReadChunkHeader(in_, &cid, &csize)) return false;
          const uint64_t cstart = static_cast<uint64_t>(in_.tellg());
          const uint64_t cend = cstart + csize + (csize & 1);
          if (cend > file_size_) return false;
          uint32_t ctype = 0;
          uint8_t avih[20];
          if (cid == FourCc("avih") && csize >= 20 &&
              in_.read(reinterpret_cast<char*>(avih), sizeof(avih))) {
            const uint32_t period_us = Le32(avih), total = Le32(avih + 16);
            if (period_us > 0) avih_fps_ = 1e6 / period_us;
            if (total > 0) avih_frames_ = total;
          } else if (cid == FourCc("LIST") && ReadFourCc(in_, &ctype) && ctype == FourCc("strl")) {
            if (!ReadStreamList(cend, stream++)) return false;
          }
          in_.seekg(static_cast<std::streamoff>(cend));
        }
        continue;
      }
    }
    if (end > file_size_) return false;
    in_.seekg(static_cast<std::streamoff>(end));
  }
  return false;
}

// One stream's 'strl' list: the first video stream in Motion-JPEG becomes the one read.
bool AviMjpegReader::ReadStreamList(uint64_t end, int index) {
  if (have_video_ || index > 99) return true;
  uint32_t id = 0, size = 0;
  bool video = false;
  uint32_t handler = 0, compression = 0, scale = 0, rate = 0, length = 0;
  while (static_cast<uint64_t>(in_.tellg()) + 8 <= end && ReadChunkHeader(in_, &id, &size)) {
    const uint64_t start = static_cast<uint64_t>(in_.tellg());
    const uint64_t cend = start + size + (size & 1);
    if (cend > end) return false;
    std::array<uint8_t, 64> b{};
    const uint32_t n = std::min<uint32_t>(size, b.size());
    if (!in_.read(reinterpret_cast<char*>(b.data()), n)) return false;
    if (id == FourCc("strh") && n >= 36) {
      video = Le32(b.data()) == FourCc("vids");
      handler = Le32(b.data() + 4);
      scale = Le32(b.data() + 20);
      rate = Le32(b.data() + 24);
      length = Le32(b.data() + 32);
    } else if (id == FourCc("strf") && n >= 20 && video) {
      width_ = static_cast<int>(Le32(b.data() + 4));
      height_ = static_cast<int>(Le32(b.data() + 8));
      compression = Le32(b.data() + 16);
    }
    in_.seekg(static_cast<std::streamoff>(cend));
  }
  if (!video || !(IsMjpeg(compression) || (compression == 0 && IsMjpeg(handler)))) return true;
  have_video_ = true;
  const char tens = static_cast<char>('0' + index / 10), ones = static_cast<char>('0' + index % 10);
  video_chunk_dc_ = static_cast<uint32_t>(codecs::FourCc(tens, ones, 'd', 'c'));
  video_chunk_db_ = static_cast<uint32_t>(codecs::FourCc(tens, ones, 'd', 'b'));
  if (scale > 0 && rate > 0) fps_ = static_cast<double>(rate) / scale;
  if (length > 0) frames_ = length;
  return true;
}

bool AviMjpegReader::Next(std::vector<uint8_t>* jpeg) {
  uint32_t id = 0, size = 0, type = 0;
  while (ReadChunkHeader(in_, &id, &size)) {
    const uint64_t start = static_cast<uint64_t>(in_.tellg());
    if (id == FourCc("RIFF") || id == FourCc("LIST")) {
      // Descend: an OpenDML 'AVIX' RIFF, its 'movi' list, a 'rec ' group of chunks.
      if (!ReadFourCc(in_, &type)) return false;
      if (type == FourCc("AVIX") || type == FourCc("movi") || type == FourCc("rec ")) continue;
    }
    const uint64_t end = start + size + (size & 1);
    if ((id == video_chunk_dc_ || id == video_chunk_db_) && size > 0) {
      if (size > kMaxFrameBytes || start + size > file_size_) return false;
      jpeg->resize(size);
      if (!in_.read(reinterpret_cast<char*>(jpeg->data()), size)) return false;
      if (size & 1) in_.seekg(static_cast<std::streamoff>(end));
      return true;
    }
    if (end > file_size_) return false;
    in_.seekg(static_cast<std::streamoff>(end));
  }
  return false;
}

}  // namespace fv::io
