// Throughput and send->receive latency of a ranger::Bus, shared by bench_bus.cpp (in-process
// loopback, Google Benchmark) and tests/bus/bench_bus_vcan.cpp (SocketCAN on vcan, runs in the VM).
// Measurement only: wall-clock time is read here and nowhere in the library's logic.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

#include "ranger_can/transport/bus.hpp"
#include "ranger_can/wire/frame.hpp"

namespace ranger::bench {

inline constexpr std::uint32_t kBenchId = 0x221;

struct ThroughputResult {
  std::uint64_t sent = 0;      // send() calls that succeeded
  std::uint64_t received = 0;  // frames the reader got
  std::uint64_t rx_dropped = 0;
  std::uint64_t tx_dropped = 0;
  double seconds = 0;  // first send to last frame received
  double received_per_second() const { return seconds > 0 ? double(received) / seconds : 0; }
};

struct LatencyResult {
  std::uint64_t samples = 0;
  double p50_us = 0, p99_us = 0, max_us = 0;
};

inline std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

inline CanFrame bench_frame(std::uint64_t payload) {
  CanFrame f;
  f.id = kBenchId;
  f.dlc = 8;
  for (int i = 0; i < 8; ++i)
    f.data[i] = static_cast<std::uint8_t>(payload >> (8 * i));
  return f;
}
inline std::uint64_t payload_of(const CanFrame& f) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i)
    v |= static_cast<std::uint64_t>(f.data[i]) << (8 * i);
  return v;
}

// Sustained throughput: `frames` sent from `tx` while a thread drains `rx`, with at most
// `window` frames in flight (sent, not yet received) so that a reader that keeps up loses
// nothing: the figure is what the bus delivers, not how fast frames can be thrown away.
// Frames lost anyway are counted (rx_dropped/tx_dropped) and the sender stops waiting for them.
inline ThroughputResult measure_throughput(Bus& tx, Bus& rx, std::uint32_t frames,
                                           std::uint32_t window = 128) {
  ThroughputResult r;
  const BusStatistics tx0 = tx.status().stats;
  const BusStatistics rx0 = rx.status().stats;
  std::atomic<std::uint64_t> seen{0};
  std::atomic<bool> sending_done{false};
  std::int64_t last_rx_ns = 0;
  std::thread reader([&] {
    for (;;) {
      auto f = rx.receive(std::chrono::milliseconds(sending_done ? 200 : 2000));
      if (!f) {
        if (sending_done) return;
        continue;
      }
      last_rx_ns = steady_ns();
      seen.fetch_add(1);
      if (payload_of(*f) == frames - 1) return;
    }
  });
  std::int64_t given_up = 0;  // frames the sender stopped waiting for (lost)
  const auto in_flight = [&] {
    return static_cast<std::int64_t>(r.sent) - given_up - static_cast<std::int64_t>(seen.load());
  };
  const std::int64_t start = steady_ns();
  for (std::uint32_t i = 0; i < frames; ++i) {
    const std::int64_t deadline = steady_ns() + 2'000'000'000;
    while (in_flight() >= window && steady_ns() < deadline)
      std::this_thread::yield();
    if (in_flight() >= window) given_up += in_flight();
    if (tx.send(bench_frame(i))) ++r.sent;
  }
  sending_done = true;
  reader.join();
  r.received = seen.load();
  r.seconds = double(std::max(last_rx_ns, start) - start) * 1e-9;
  r.rx_dropped = rx.status().stats.rx_dropped - rx0.rx_dropped;
  r.tx_dropped = tx.status().stats.tx_dropped - tx0.tx_dropped;
  return r;
}

// One frame in flight at a time: the time from just before send() to the moment a reader
// thread blocked in receive() has it.
inline LatencyResult measure_latency(Bus& tx, Bus& rx, std::uint32_t samples) {
  std::vector<double> us;
  us.reserve(samples);
  std::atomic<std::uint32_t> seen{0};
  std::thread reader([&] {
    while (seen.load() < samples) {
      auto f = rx.receive(std::chrono::seconds(2));
      if (!f) return;  // lost: the sender stops waiting below
      us.push_back(double(steady_ns() - static_cast<std::int64_t>(payload_of(*f))) * 1e-3);
      seen.fetch_add(1);
    }
  });
  std::uint32_t in_flight_done = 0;  // frames sent successfully so far
  for (std::uint32_t i = 0; i < samples; ++i) {
    if (!tx.send(bench_frame(static_cast<std::uint64_t>(steady_ns())))) continue;
    ++in_flight_done;
    const std::int64_t deadline = steady_ns() + 2'000'000'000;
    while (seen.load() < in_flight_done && steady_ns() < deadline)
      std::this_thread::yield();
    if (seen.load() < in_flight_done) break;  // lost: stop rather than wait on every sample
  }
  reader.join();
  LatencyResult r;
  r.samples = us.size();
  if (us.empty()) return r;
  std::sort(us.begin(), us.end());
  const auto at = [&](double q) {
    return us[std::min(us.size() - 1,
                       static_cast<std::size_t>(q * static_cast<double>(us.size())))];
  };
  r.p50_us = at(0.50);
  r.p99_us = at(0.99);
  r.max_us = us.back();
  return r;
}

}  // namespace ranger::bench
