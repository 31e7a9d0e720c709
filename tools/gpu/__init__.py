"""What runs on a GPU machine: check.sh (`make gpu-check OUT=DIR`) builds, tests and
benchmarks the CUDA labs and ends with report.py (`python3 -m tools.gpu.report`);
tradeoff.sh (`make tradeoff-gpu OUT=DIR`) measures make tradeoff's GPU rows."""
