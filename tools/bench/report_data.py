"""The course report's own numbers, for `make bench` to print beside this machine's.

Source: the course report "Parallel Ray Tracer" (Team 8), Section 6 "Experimental Results",
Tables 4-7, measured on an Intel Core i5-7500 @ 3.4 GHz (4 cores) with an NVIDIA Tesla T4
(its Table 3); OpenMP ran 4 threads and MPI 8 processes (the tables' footnotes). Every number
below was read from the report's text; none is left out as unreadable.

Each entry: (table, the row as the report prints it, the binary here it is paired with,
setting value, seconds, the speedup the report prints). The report's speedups are over its
own first row (Table 4: serial without SIMD, 102.46 s; Tables 5-7: the row "Serial", whose
baseline time, 95.00 s, is Table 4's serial *with* SIMD). Some printed speedups disagree
with the report's own times and are kept as printed: Table 6's CUDA at 512 spp says 30.25x
where Tables 5 and 7 print 30.45x for the same 95.00 / 3.12 s; MPI at the baseline in
Tables 5-7 says 6.55x, Table 4's 102.46 / 15.65, not 95.00 / 15.65 = 6.07x.

Pairing. The report's SIMD vectorises the Vec3 type (its Table 2: the "C" loop), which is
lab 02's Part A (lab02a-ref); this repository's OpenMP and MPI + SIMD references use lab 02's
AVX2 packets (Part B) instead, the nearest it has. Tables 5-7 print one row per method; their
baseline column equals Table 4's SIMD rows (95.00, 38.90, 15.65 s) and the split-kernel CUDA
row (3.12 s), so they are paired with those binaries.
"""

# The report's settings: the baseline, and the three sweeps (Section 5).
BASELINE = {"size": 600, "spp": 512, "bounces": 4}
SWEEPS = {
    "size": (150, 300, 600),    # Table 5: image side in pixels (square images)
    "spp": (256, 512, 1024),    # Table 6: samples per pixel
    "bounces": (2, 4, 8),       # Table 7: maximum bounces per ray
}
TABLE = {"baseline": 4, "size": 5, "spp": 6, "bounces": 7}

REPORT_MACHINE = "Intel Core i5-7500 @ 3.4 GHz (OpenMP 4 threads, MPI 8 processes), NVIDIA Tesla T4"

# (experiment, report row, paired binary, setting value, seconds, printed speedup)
ROWS = [
    # Table 4: the baseline (600x600, 512 spp, 4 bounces). Setting value: None.
    ("baseline", "Serial", "lab01-ref", None, 102.46, 1.00),
    ("baseline", "Serial + SIMD", "lab02a-ref", None, 95.00, 1.08),
    ("baseline", "OpenMP", "lab03-ref", None, 39.65, 2.58),
    ("baseline", "OpenMP + SIMD", "lab03-simd-ref", None, 38.90, 2.63),
    ("baseline", "MPI", "lab04-ref", None, 15.75, 6.51),
    ("baseline", "MPI + SIMD", "lab04-simd-ref", None, 15.65, 6.55),
    ("baseline", "CUDA (Mega)", "lab05-ref", None, 6.64, 15.43),
    ("baseline", "CUDA (Split)", "lab06-ref", None, 3.12, 32.84),
    # Table 5: image size.
    ("size", "Serial", "lab02a-ref", 150, 5.99, 1.00),
    ("size", "Serial", "lab02a-ref", 300, 25.08, 1.00),
    ("size", "Serial", "lab02a-ref", 600, 95.00, 1.00),
    ("size", "OpenMP", "lab03-simd-ref", 150, 2.98, 2.01),
    ("size", "OpenMP", "lab03-simd-ref", 300, 9.70, 2.58),
    ("size", "OpenMP", "lab03-simd-ref", 600, 38.90, 2.44),
    ("size", "MPI", "lab04-simd-ref", 150, 3.52, 1.70),
    ("size", "MPI", "lab04-simd-ref", 300, 4.59, 5.46),
    ("size", "MPI", "lab04-simd-ref", 600, 15.65, 6.55),
    ("size", "CUDA", "lab06-ref", 150, 0.39, 15.36),
    ("size", "CUDA", "lab06-ref", 300, 0.92, 27.26),
    ("size", "CUDA", "lab06-ref", 600, 3.12, 30.45),
    # Table 6: samples per pixel.
    ("spp", "Serial", "lab02a-ref", 256, 47.43, 1.00),
    ("spp", "Serial", "lab02a-ref", 512, 95.00, 1.00),
    ("spp", "Serial", "lab02a-ref", 1024, 189.46, 1.00),
    ("spp", "OpenMP", "lab03-simd-ref", 256, 24.22, 1.96),
    ("spp", "OpenMP", "lab03-simd-ref", 512, 38.90, 2.44),
    ("spp", "OpenMP", "lab03-simd-ref", 1024, 77.79, 2.44),
    ("spp", "MPI", "lab04-simd-ref", 256, 8.32, 5.7),
    ("spp", "MPI", "lab04-simd-ref", 512, 15.65, 6.55),
    ("spp", "MPI", "lab04-simd-ref", 1024, 30.29, 6.25),
    ("spp", "CUDA", "lab06-ref", 256, 1.64, 28.92),
    ("spp", "CUDA", "lab06-ref", 512, 3.12, 30.25),
    ("spp", "CUDA", "lab06-ref", 1024, 6.02, 31.47),
    # Table 7: bounces per ray.
    ("bounces", "Serial", "lab02a-ref", 2, 49.78, 1.00),
    ("bounces", "Serial", "lab02a-ref", 4, 95.00, 1.00),
    ("bounces", "Serial", "lab02a-ref", 8, 146.39, 1.00),
    ("bounces", "OpenMP", "lab03-simd-ref", 2, 21.83, 2.28),
    ("bounces", "OpenMP", "lab03-simd-ref", 4, 38.90, 2.44),
    ("bounces", "OpenMP", "lab03-simd-ref", 8, 60.15, 2.43),
    ("bounces", "MPI", "lab04-simd-ref", 2, 7.94, 6.27),
    ("bounces", "MPI", "lab04-simd-ref", 4, 15.65, 6.55),
    ("bounces", "MPI", "lab04-simd-ref", 8, 24.82, 5.90),
    ("bounces", "CUDA", "lab06-ref", 2, 2.21, 22.52),
    ("bounces", "CUDA", "lab06-ref", 4, 3.12, 30.45),
    ("bounces", "CUDA", "lab06-ref", 8, 4.02, 36.42),
]
