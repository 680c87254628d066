// The in-process loopback bus: cost of one send+receive, sustained throughput with a reader
// thread, and send->receive latency (p50/p99) with the reader blocked in receive().
//   bench_bus --benchmark_counters_tabular=true
// The same measurements on vcan: tests/bus/bench_bus_vcan (run it in the VM, see PERFORMANCE.md).
#include <benchmark/benchmark.h>

#include "bus_bench.hpp"
#include "ranger_can/transport/loopback_bus.hpp"

namespace {

using ranger::LoopbackNetwork;
using ranger::LoopbackOptions;

LoopbackOptions bench_options() {
  LoopbackOptions o;
  o.filter = {};  // deliver every ID
  o.rx_queue_capacity = 4096;
  return o;
}

void BM_LoopbackSendThenReceive(benchmark::State& state) {
  LoopbackNetwork net(bench_options());
  auto a = net.connect();
  auto b = net.connect();
  std::uint64_t i = 0;
  for (auto _ : state) {
    a->send(ranger::bench::bench_frame(i++));
    auto f = b->receive(std::chrono::seconds(1));
    benchmark::DoNotOptimize(f);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_LoopbackSendThenReceive);

void BM_LoopbackThroughputWithReaderThread(benchmark::State& state) {
  const auto frames = static_cast<std::uint32_t>(state.range(0));
  double per_second = 0, dropped = 0;
  for (auto _ : state) {
    LoopbackNetwork net(bench_options());
    auto a = net.connect();
    auto b = net.connect();
    const auto r = ranger::bench::measure_throughput(*a, *b, frames);
    per_second = r.received_per_second();
    dropped = double(r.rx_dropped + r.tx_dropped);
  }
  state.counters["frames_per_s"] = per_second;
  state.counters["dropped"] = dropped;
}
BENCHMARK(BM_LoopbackThroughputWithReaderThread)->Arg(100000)->Iterations(3)->UseRealTime();

void BM_LoopbackLatency(benchmark::State& state) {
  const auto samples = static_cast<std::uint32_t>(state.range(0));
  ranger::bench::LatencyResult r;
  for (auto _ : state) {
    LoopbackNetwork net(bench_options());
    auto a = net.connect();
    auto b = net.connect();
    r = ranger::bench::measure_latency(*a, *b, samples);
  }
  state.counters["p50_us"] = r.p50_us;
  state.counters["p99_us"] = r.p99_us;
  state.counters["max_us"] = r.max_us;
  state.counters["samples"] = double(r.samples);
}
BENCHMARK(BM_LoopbackLatency)->Arg(20000)->Iterations(1)->UseRealTime();

}  // namespace
