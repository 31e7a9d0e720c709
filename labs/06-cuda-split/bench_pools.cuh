// The path-pool layouts lab06-bench measures: lab 06's array of structures. Lab 07's folder
// holds a file of the same name, earlier on lab07-bench's include path, that adds its
// structure of arrays, so that one benchmark source measures both in the same run.
#pragma once

#include "path_pool_aos.cuh"

template <class... Pools>
struct PoolList {};
using BenchPools = PoolList<AosPathPool>;
