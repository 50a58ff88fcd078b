#include "fieldvision/io/jpeg_orientation.h"

#include <cstring>

namespace fv::io {
namespace {

// A TIFF structure's integers in its byte order ("II" little, "MM" big endian).
struct TiffReader {
  const uint8_t* data;
  size_t size;
  bool little;
  bool U16(size_t at, unsigned* v) const {
    if (at + 2 > size) return false;
    *v = little ? data[at] | data[at + 1] << 8 : data[at] << 8 | data[at + 1];
    return true;
  }
  bool U32(size_t at, uint32_t* v) const {
    unsigned a = 0, b = 0;
    if (!U16(at, &a) || !U16(at + 2, &b)) return false;
    *v = little ? (uint32_t(b) << 16 | a) : (uint32_t(a) << 16 | b);
    return true;
  }
};

// The orientation in an APP1 payload ("Exif\0\0" then a TIFF header and IFD0); 1 when none.
int OrientationInExif(const uint8_t* p, size_t n) {
  if (n < 14 || std::memcmp(p, "Exif\0\0", 6) != 0) return 1;
  const uint8_t* tiff = p + 6;
  const size_t size = n - 6;
  TiffReader r{tiff, size, tiff[0] == 'I'};
  if (!(tiff[0] == tiff[1] && (tiff[0] == 'I' || tiff[0] == 'M'))) return 1;
  unsigned magic = 0, entries = 0;
  uint32_t ifd = 0;
  if (!r.U16(2, &magic) || magic != 42 || !r.U32(4, &ifd) || !r.U16(ifd, &entries)) return 1;
  for (unsigned i = 0; i < entries; ++i) {
    const size_t at = size_t(ifd) + 2 + 12 * size_t(i);
    unsigned tag = 0, type = 0, value = 0;
    if (!r.U16(at, &tag) || !r.U16(at + 2, &type)) return 1;
    if (tag != 0x0112) continue;
    if (type != 3 || !r.U16(at + 8, &value)) return 1;  // SHORT, stored in the entry
    return value >= 1 && value <= 8 ? static_cast<int>(value) : 1;
  }
  return 1;
}

}  // namespace

int JpegOrientation(const uint8_t* data, size_t size) {
  if (data == nullptr || size < 4 || data[0] != 0xFF || data[1] != 0xD8) return 1;
  size_t at = 2;
  // The marker segments before the scan: FF xx, then a big-endian length that counts itself.
  while (at + 4 <= size && data[at] == 0xFF) {
    const uint8_t marker = data[at + 1];
    if (marker == 0xFF) {  // fill byte
      ++at;
      continue;
    }
    if (marker == 0xDA || marker == 0xD9) break;  // start of scan, end of image
    const size_t length = size_t(data[at + 2]) << 8 | data[at + 3];
    if (length < 2 || at + 2 + length > size) break;
    if (marker == 0xE1) {
      const int o = OrientationInExif(data + at + 4, length - 2);
      if (o != 1) return o;
    }
    at += 2 + length;
  }
  return 1;
}

}  // namespace fv::io
