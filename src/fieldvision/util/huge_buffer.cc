#include "fieldvision/util/huge_buffer.h"

#include <cstdlib>
#include <utility>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "fieldvision/util/error.h"

namespace fv::util {
namespace {
constexpr size_t kHugePage = size_t(2) << 20;
}  // namespace

HugeBuffer::HugeBuffer(size_t bytes) : size_(bytes) {
  if (bytes == 0) return;
#if defined(__linux__)
  // Map one huge page more than rounded up, keep the 2 MiB-aligned part, unmap the rest.
  const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  const size_t length = rounded + kHugePage;
  void* p = bytes < kHugePage
                ? MAP_FAILED
                : mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (bytes >= kHugePage && p != MAP_FAILED) {
    char* const start = static_cast<char*>(p);
    const size_t skip = (kHugePage - reinterpret_cast<uintptr_t>(p) % kHugePage) % kHugePage;
    char* const aligned = start + skip;
    if (skip > 0) munmap(start, skip);
    if (length > skip + rounded) munmap(aligned + rounded, length - skip - rounded);
    mapping_ = aligned;
    mapped_ = rounded;
    // Only a hint: without huge pages the mapping is ordinary zeroed memory.
    madvise(mapping_, mapped_, MADV_HUGEPAGE);
    data_ = static_cast<uint8_t*>(mapping_);
    return;
  }
#endif
  mapping_ = std::calloc(bytes, 1);
  FV_REQUIRE(mapping_ != nullptr, "out of memory for a {} byte table", bytes);
  data_ = static_cast<uint8_t*>(mapping_);
}

HugeBuffer::~HugeBuffer() { Release(); }

HugeBuffer::HugeBuffer(HugeBuffer&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      mapping_(std::exchange(other.mapping_, nullptr)),
      mapped_(std::exchange(other.mapped_, 0)) {}

HugeBuffer& HugeBuffer::operator=(HugeBuffer&& other) noexcept {
  if (this != &other) {
    Release();
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
    mapping_ = std::exchange(other.mapping_, nullptr);
    mapped_ = std::exchange(other.mapped_, 0);
  }
  return *this;
}

void HugeBuffer::Release() {
  if (mapping_ == nullptr) return;
#if defined(__linux__)
  if (mapped_ > 0) {
    munmap(mapping_, mapped_);
    mapping_ = nullptr;
    return;
  }
#endif
  std::free(mapping_);
  mapping_ = nullptr;
}

}  // namespace fv::util
