// Throughput and send->receive latency of a real SocketCAN interface (or, for comparison, the
// in-process loopback), with the same method as libranger_can/bench/bench_bus.cpp:
//   bench_bus_vcan [--interface vcan0 | --loopback] [--frames 100000] [--samples 20000]
// Needs the interface up; inside the VM: tests/vm/run_in_vm.sh "<build>/tests/bus/bench_bus_vcan".
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "bus_bench.hpp"
#include "ranger_can/transport/loopback_bus.hpp"
#include "ranger_can/transport/socketcan_bus.hpp"

int main(int argc, char** argv) {
  std::string interface = "vcan0";
  bool loopback = false;
  unsigned long frames = 100000, samples = 20000;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--interface" && has_value) {
      interface = argv[++i];
    } else if (a == "--loopback") {
      loopback = true;
    } else if (a == "--frames" && has_value) {
      frames = std::strtoul(argv[++i], nullptr, 10);
    } else if (a == "--samples" && has_value) {
      samples = std::strtoul(argv[++i], nullptr, 10);
    } else {
      std::fprintf(stderr, "usage: %s [--interface NAME | --loopback] [--frames N] [--samples N]\n",
                   argv[0]);
      return 2;
    }
  }

  std::unique_ptr<ranger::LoopbackNetwork> network;
  std::unique_ptr<ranger::Bus> tx, rx;
  if (loopback) {
    ranger::LoopbackOptions o;
    o.filter = {};
    o.rx_queue_capacity = 4096;
    network = std::make_unique<ranger::LoopbackNetwork>(o);
    tx = network->connect();
    rx = network->connect();
    interface = "loopback";
  } else {
    ranger::SocketCanOptions o;
    o.filter = {ranger::bench::kBenchId};
    auto a = ranger::SocketCanBus::open(interface, o);
    auto b = ranger::SocketCanBus::open(interface, o);
    if (!a || !b) {
      std::fprintf(stderr, "bench_bus_vcan: %s\n", (!a ? a.error() : b.error()).message.c_str());
      return 1;
    }
    tx = std::move(a).value();
    rx = std::move(b).value();
  }

  const auto t = ranger::bench::measure_throughput(*tx, *rx, static_cast<std::uint32_t>(frames));
  std::printf(
      "%s throughput: %lu frames, at most 128 in flight: %llu received, %llu rx dropped, "
      "%llu tx dropped, %.3f s -> %.0f frames/s\n",
      interface.c_str(), frames, static_cast<unsigned long long>(t.received),
      static_cast<unsigned long long>(t.rx_dropped), static_cast<unsigned long long>(t.tx_dropped),
      t.seconds, t.received_per_second());
  const auto l = ranger::bench::measure_latency(*tx, *rx, static_cast<std::uint32_t>(samples));
  std::printf(
      "%s latency (send -> blocked reader has it, one frame in flight): %llu samples, "
      "p50 %.1f us, p99 %.1f us, max %.1f us\n",
      interface.c_str(), static_cast<unsigned long long>(l.samples), l.p50_us, l.p99_us, l.max_us);
  return l.samples == samples ? 0 : 1;
}
