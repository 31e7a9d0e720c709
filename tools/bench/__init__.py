"""Benchmarks that print tables: each module is a command, `python3 -m tools.bench.NAME`,
behind a make target (`make help`): cpu (bench-cpu), serial (bench-serial), simd
(bench-simd), openmp (bench-openmp), mpi (bench-mpi), precision (bench-precision), report
(bench: the course report's Tables 4-7), count_work (count-work)."""
