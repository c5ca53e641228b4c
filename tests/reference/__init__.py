"""Straightforward NumPy references of the C++ kernels, shared by tests/ and bench/.

One module per wing: ``kernels`` (HSV bins, histograms, Bhattacharyya, resampling, SIS),
``fused`` (vectorised NumPy peers for the benchmarks), ``mcmc`` (MH and RJ-MCMC), ``detection``
(background model), ``refine`` (box refinement), ``blobs`` (the blob pass and
the size model's kernels), ``smoothing`` (constant-velocity posterior),
``bridge`` (goal-directed recovery), ``mixture`` (stand/walk gap mixture), ``neighbours``
(the `-nb` methods' neighbour search), ``text`` (MOTChallenge lines, Python's ``%``), ``boxes``
(intersection and IoU, pair by pair), ``crossings`` (the offline crossing repair, one window
at a time).
"""
