// Time to plan a recording (gravcal plan): the target-weighted design over
// the free pose set (2000 directions on the sphere plus faces+45), the seed
// schemes' comparison and the handling order with the turns between poses.
#include <benchmark/benchmark.h>

#include "gravcal/workflows/config.h"
#include "gravcal/workflows/plan.h"

namespace gravcal {
namespace {

// range(0): free candidate directions; range(1): 0 = loose targets,
// 1 = demanding targets (more poses, longer holds); range(2): 1 = with the
// gyroscope (full model): its turns chosen and, for its targets, extra poses.
void BM_PlanFree(benchmark::State& state) {
  Config config;
  PlanRequest request;
  request.pose_set = PoseSet::kFree;
  request.free_candidates = static_cast<int>(state.range(0));
  request.accel_noise_density = 0.002;
  request.targets = state.range(1) == 0
                        ? "accel_bias=0.5mg accel_scale=200ppm accel_misalignment=0.2mrad"
                        : "accel_bias=0.02mg accel_scale=10ppm accel_misalignment=0.01mrad";
  if (state.range(2) == 1) {
    config.gyro.parameterization = GyroParameterization::kFull;
    request.gyro_noise_density = 2e-4;
    request.targets += " gyro_scale=200ppm gyro_misalignment=0.5mrad";
  }
  for (auto _ : state) {
    RecordingPlan plan;
    std::string error;
    if (!MakeRecordingPlan(config, request, &plan, &error)) {
      state.SkipWithError(error.c_str());
      return;
    }
    benchmark::DoNotOptimize(plan.total_seconds);
  }
}
BENCHMARK(BM_PlanFree)
    ->Args({2000, 0, 0})
    ->Args({2000, 1, 0})
    ->Args({500, 1, 0})
    ->Args({2000, 0, 1})
    ->Args({2000, 1, 1})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gravcal

BENCHMARK_MAIN();
