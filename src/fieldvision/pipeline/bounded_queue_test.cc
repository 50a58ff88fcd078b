#include "fieldvision/pipeline/bounded_queue.h"

#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace fv::pipeline {
namespace {

TEST(BoundedQueue, BlockingQueueLosesNothingAndKeepsOrder) {
  BoundedQueue<int> q(3, QueuePolicy::kBlock);
  const int n = 2000;
  std::thread producer([&] {
    for (int i = 0; i < n; ++i) ASSERT_TRUE(q.Push(i));
    q.Close();
  });
  std::vector<int> got;
  while (auto v = q.Pop()) {
    EXPECT_LE(q.size(), 3u);
    got.push_back(*v);
  }
  producer.join();
  ASSERT_EQ(static_cast<int>(got.size()), n);
  for (int i = 0; i < n; ++i) EXPECT_EQ(got[i], i);
  EXPECT_EQ(q.dropped(), 0u);
}

TEST(BoundedQueue, DropOldestKeepsTheNewest) {
  BoundedQueue<int> q(3, QueuePolicy::kDropOldest);
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(q.Push(i));
  EXPECT_EQ(q.dropped(), 7u);
  EXPECT_EQ(q.size(), 3u);
  EXPECT_EQ(*q.Pop(), 7);
  EXPECT_EQ(*q.Pop(), 8);
  EXPECT_EQ(*q.Pop(), 9);
  EXPECT_FALSE(q.TryPop().has_value());
}

TEST(BoundedQueue, CloseWakesABlockedProducerAndDrainsForTheConsumer) {
  BoundedQueue<int> q(1, QueuePolicy::kBlock);
  ASSERT_TRUE(q.Push(1));
  bool second = true;
  std::thread producer([&] { second = q.Push(2); });  // blocks: the queue is full
  q.Close();
  producer.join();
  EXPECT_FALSE(second);
  EXPECT_EQ(*q.Pop(), 1);  // what was queued is still delivered
  EXPECT_FALSE(q.Pop().has_value());
  EXPECT_FALSE(q.Push(3));
  EXPECT_THROW(BoundedQueue<int>(0, QueuePolicy::kBlock), Error);
}

}  // namespace
}  // namespace fv::pipeline
