// The path-pool layouts lab07-bench measures, in the same run on the same scene: lab 06's
// array of structures and this lab's structure of arrays (labs/06-cuda-split/bench.cu).
#pragma once

#include "path_pool_aos.cuh"
#include "path_pool_soa.cuh"

template <class... Pools>
struct PoolList {};
using BenchPools = PoolList<AosPathPool, SoaPathPool>;
