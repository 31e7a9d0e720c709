"""Autograder helpers: PFM I/O (pfm), statistical image comparison (compare), heatmaps."""
