// A zero-filled byte buffer on transparent huge pages where the kernel offers them (Linux, from
// 2 MiB: an anonymous mapping aligned to 2 MiB, madvise MADV_HUGEPAGE; else plain memory). For the
// colour lookup tables: a 16 MB table filled on 4 KiB pages takes 4096 page faults (a large part
// of a short run's start) and its random reads, one per classified pixel, miss the TLB; on 2 MiB
// pages, 8 faults and 8 TLB entries.
#pragma once

#include <cstddef>
#include <cstdint>

namespace fv::util {

class HugeBuffer {
 public:
  HugeBuffer() = default;
  explicit HugeBuffer(size_t bytes);  // zero-filled; throws fv::Error when out of memory
  ~HugeBuffer();
  HugeBuffer(HugeBuffer&& other) noexcept;
  HugeBuffer& operator=(HugeBuffer&& other) noexcept;
  HugeBuffer(const HugeBuffer&) = delete;
  HugeBuffer& operator=(const HugeBuffer&) = delete;

  uint8_t* data() { return data_; }
  const uint8_t* data() const { return data_; }
  size_t size() const { return size_; }
  uint8_t& operator[](size_t i) { return data_[i]; }
  const uint8_t& operator[](size_t i) const { return data_[i]; }

 private:
  void Release();
  uint8_t* data_ = nullptr;
  size_t size_ = 0;
  void* mapping_ = nullptr;  // what to unmap or free
  size_t mapped_ = 0;        // its length (0: freed with std::free)
};

}  // namespace fv::util
