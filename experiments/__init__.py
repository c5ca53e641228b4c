"""Experiment scripts behind the figures in README.md and docs/ (not part of the pftrack package).

Each module is run from the repository root as ``python -m experiments.NAME [--out DIR]``; it
prints its tables and writes them, with any figures, to ``DIR`` (default ``out/NAME``, which git
ignores). Real sequences are read from ``--data``, else ``$PFTRACK_DATA``, else
``../shared/data``.

=========================  ====================================================================
``compare_trackers``       pftrack against SORT, ByteTrack, norfair and motpy on the same boxes
``compare_stonesoup``      pftrack against a Stone Soup tracker and its Kalman smoother
``detector_robustness``    the built-in detector on grey, darkening and cropped variants
``eval_detection``         a detector's precision and recall on PETS09-S2L1
``frame_rate``             every sequence at full, half and third rate, detections on odd frames
``offline_sensitivity``    MOTA / IDF1 under changed association and smoother defaults
``recovery_linking_pets``  linking and filling of PETS09-S2L1 ground truth cut into fragments
``linking_wrong_joins``    ``pftrack smooth``'s wrong joins on the five ground truths in pieces
``recovery_variants``      model variants of ``gdt-bi`` on the paper's mask protocol
``rjmcmc_speed``           RJ-MCMC frames/s and MH vs SIS per-object cost on PETS09-S2L1
``sampler_experiment``     SIS vs MH vs RJ-MCMC inside the tracker: scores, timing, occlusion
=========================  ====================================================================
"""
