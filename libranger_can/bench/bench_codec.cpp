// Cost of the codec: decode and encode per frame for every ID, and the host's real workload, one
// 20 ms feedback cycle (13 frames: 0x211, 0x221, 0x251-0x258, 0x271, 0x281, 0x291) decoded.
// Target: a full cycle in under 1 us.
//
//   bench_codec                                   Google Benchmark (wall-clock, noisy machines:
//                                                 use --benchmark_repetitions=5 and the median)
//   bench_codec --callgrind-cycles=N              decode N cycles and exit, for instruction counts:
//     valgrind --tool=callgrind --callgrind-out-file=/dev/null bench_codec --callgrind-cycles=1000
//     valgrind --tool=callgrind --callgrind-out-file=/dev/null bench_codec
//     --callgrind-cycles=101000 instructions per frame = (Ir(101000) - Ir(1000)) / (100000 * 13)
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace {

using ranger::CanFrame;
namespace proto = ranger::protocol;

// A plausible payload for `id`: decodable, with non-zero fields so no path is trivially short.
CanFrame sample_frame(std::uint32_t id) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(proto::layout_dlc(id));
  const std::uint8_t pattern[8] = {0x00, 0x96, 0x01, 0x2C, 0xFF, 0x6A, 0x03, 0xE8};
  for (int i = 0; i < f.dlc; ++i)
    f.data[static_cast<std::size_t>(i)] = pattern[i];
  if (f.dlc == 1) f.data[0] = 0x01;
  if (id == proto::kMotionModeFeedbackId) f.data[0] = 0x00;
  return f;
}

std::vector<CanFrame> feedback_cycle() {
  std::vector<CanFrame> cycle = {sample_frame(proto::kSystemStatusId),
                                 sample_frame(proto::kMotionFeedbackId)};
  for (std::uint32_t m = 1; m <= 8; ++m)
    cycle.push_back(sample_frame(proto::kMotorHighSpeedBaseId + m));
  cycle.push_back(sample_frame(proto::kSteeringAnglesId));
  cycle.push_back(sample_frame(proto::kWheelSpeedsId));
  cycle.push_back(sample_frame(proto::kMotionModeFeedbackId));
  return cycle;  // 13 frames
}

void BM_Decode(benchmark::State& state) {
  const CanFrame f = sample_frame(static_cast<std::uint32_t>(state.range(0)));
  state.SetLabel(std::string(proto::frame_name(f.id)));
  for (auto _ : state) {
    auto m = ranger::decode(f);
    benchmark::DoNotOptimize(m);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_Encode(benchmark::State& state) {
  const auto message = ranger::decode(sample_frame(static_cast<std::uint32_t>(state.range(0))));
  if (!message.ok()) {
    state.SkipWithError(message.error().message.c_str());
    return;
  }
  state.SetLabel(std::string(proto::frame_name(static_cast<std::uint32_t>(state.range(0)))));
  const ranger::Message m = *message;
  for (auto _ : state) {
    auto f = ranger::encode(m);
    benchmark::DoNotOptimize(f);
  }
  state.SetItemsProcessed(state.iterations());
}

void register_per_id() {
  for (std::uint32_t id : proto::all_ids()) {
    benchmark::RegisterBenchmark("BM_Decode", BM_Decode)->Arg(id);
    benchmark::RegisterBenchmark("BM_Encode", BM_Encode)->Arg(id);
  }
}

void BM_DecodeFeedbackCycle(benchmark::State& state) {
  const std::vector<CanFrame> cycle = feedback_cycle();
  for (auto _ : state) {
    for (const CanFrame& f : cycle) {
      auto m = ranger::decode(f);
      benchmark::DoNotOptimize(m);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(cycle.size()));
  state.counters["frames_per_cycle"] = static_cast<double>(cycle.size());
}
BENCHMARK(BM_DecodeFeedbackCycle);

// The error paths build a message string (they allocate); shown for completeness.
void BM_DecodeBadDlc(benchmark::State& state) {
  CanFrame f = sample_frame(proto::kMotionFeedbackId);
  f.dlc = 6;
  for (auto _ : state) {
    auto m = ranger::decode(f);
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_DecodeBadDlc);

void BM_DecodeUnknownId(benchmark::State& state) {
  CanFrame f = sample_frame(proto::kMotionFeedbackId);
  f.id = 0x701;
  for (auto _ : state) {
    auto m = ranger::decode(f);
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_DecodeUnknownId);

// Plain loop for instruction counting under callgrind (no benchmark framework around it).
int run_cycles_for_callgrind(long cycles) {
  const std::vector<CanFrame> cycle = feedback_cycle();
  unsigned long checksum = 0;
  for (long i = 0; i < cycles; ++i) {
    for (const CanFrame& f : cycle) {
      auto m = ranger::decode(f);
      benchmark::DoNotOptimize(m);
      checksum += m.ok() ? m->index() : 100;
    }
  }
  std::printf("decoded %ld cycles x %zu frames (checksum %lu)\n", cycles, cycle.size(), checksum);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  constexpr const char* kCallgrindFlag = "--callgrind-cycles=";
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], kCallgrindFlag, std::strlen(kCallgrindFlag)) == 0) {
      return run_cycles_for_callgrind(std::atol(argv[i] + std::strlen(kCallgrindFlag)));
    }
  }
  register_per_id();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
