"""The run folder: its layout, its file names and the schema of every file in it.

A run folder ``<out>/<case>/<vut>/seed_<k>/`` (:meth:`StudyFolder.run`) holds, per stage:

======================  ===========================  =========================================
file                    writer / reader              what
======================  ===========================  =========================================
``config.yaml``         write_/read_run_config       configuration (VUT: ``env.vut``), ``seed``
``command.txt``         write_/read_command          the command line
``versions.json``       write_/read_versions         Python, platform and package versions
``seeds.json``          write_/read_seeds            training, SUMO and evaluation seeds
``eval.csv``            write_/read_eval_table       one row per SPCP candidate
``checkpoints/``        (:mod:`sumo_ayss.training.   ``step_XXXXXXXXX/model.zip`` per
                        checkpoint_files`)           candidate; the latest also holds the
                                                     resume state; ``latest.json`` names it
``spcp.json``           write_/read_spcp             the selected candidate and why
``spcp.zip``            (a copy of its model.zip)    the SPCP
``progress.json``       write_/read_progress         stage, step, rate, for watchers
``tb/``                 (TensorBoard)                training logs
``outcome.csv``         write_/read_table            one row per outcome episode
                        (:data:`OUTCOME_SCHEMA`)
``outcome.json``        write_/read_outcome_json     rates and means with 95 % intervals
``ayss.csv``            write_/read_table            one row per kept AYSS sample
                        (:data:`AYSS_SCHEMA`)
``ayss_bins.csv``       write_/read_ayss_bins        the AYSS samples as moments (n, mean,
                        (:data:`AYSS_BINS_SCHEMA`)   m2) per 1/32 m headway cell: small,
                                                     committed where ``ayss.csv`` is not;
                                                     the AYSS figures, table and paper mode
                                                     read it when ``ayss.csv`` is absent
                                                     (:mod:`.ayss_bins`)
``ayss.json``           write_/read_ayss_json        filter counts, settings, throughput
``evaluate.done.json``  write_/read_done_marker      the pipeline's evaluation marker
``job.log``             (logging)                    the pipeline job's log
``renamed.json``        (:mod:`sumo_ayss.grid.study`) a VUT renamed without change: the
                                                     name it was trained under
======================  ===========================  =========================================

The case folder ``<out>/<case>/`` (:meth:`StudyFolder.case`, :class:`CaseFolder`), one level
above the case's run folders, holds the cross-play and discriminability stages' files:

==========================  ==============================  ==================================
``crossplay.csv``           write_/read_table               one row per (VUT, opponent SPCP,
                            (:data:`CROSSPLAY_SCHEMA`)      scenario)
``crossplay.json``          write_/read_crossplay_json      settings, opponents, VUT keys,
                                                            wall time
``crossplay.partial/``      :class:`CellStore`              finished cells of an unfinished
                                                            table, removed once it is written
``discriminability.json``   write_discriminability /        where the VUTs' responses differ
``discriminability.csv``    read_discriminability_json      over the AYSS box
``adaptive.json``           write_/read_adaptive            adaptive seeding: looks, seeds,
                                                            the VUTs looked at
``.superseded/``            (:mod:`sumo_ayss.grid.study`)   runs of redefined VUTs, set aside
==========================  ==============================  ==================================

A study's runs are found, checked to be poolable and grouped by case, each case with its
cross-play table, by :mod:`.study_runs` (:func:`load_runs`, :func:`case_runs`).

The study folder ``<out>/`` (:class:`StudyFolder`) holds ``pipeline.json``, ``ranking.csv``,
``ranking.md``, ``order_check.json`` and ``measures.csv`` (:mod:`.study`).

A run folder is read once into a :class:`RunRecord` (:func:`read_run`, :mod:`.record`) and
that record is handed on; a case's cross-play table is read by :func:`load_crossplay`.
Whether a stage is done with the inputs asked for now is decided above the files
(:mod:`sumo_ayss.stages`), from the markers read here.

Every file is written atomically (:mod:`sumo_ayss.util.atomic`). No other module spells one of
these names or parses one of these files: the tables go through the one CSV reader and writer,
the JSON files through the one JSON reader (:mod:`sumo_ayss.records`, which knows no file of
the run folder; the schemas are here). Imports neither SUMO nor torch.
"""

from __future__ import annotations

from sumo_ayss.run_folder.adaptive import (
    AdaptiveLook,
    AdaptiveRecord,
    read_adaptive,
    write_adaptive,
)
from sumo_ayss.run_folder.crossplay import (
    CrossplayOpponent,
    CrossplayRecord,
    DiagonalCheck,
    read_crossplay_json,
    read_inevitable,
    write_crossplay_json,
    write_inevitable,
)
from sumo_ayss.run_folder.crossplay_partial import CellStore
from sumo_ayss.run_folder.discriminability import (
    read_discriminability_json,
    write_discriminability,
)
from sumo_ayss.run_folder.eval_table import (
    EVAL_SCHEMA,
    read_eval_table,
    write_eval_table,
)
from sumo_ayss.run_folder.layout import (
    CaseFolder,
    RunFolder,
    find_run_dirs,
)
from sumo_ayss.run_folder.metadata import (
    RunConfig,
    Seeds,
    read_done_marker,
    read_progress,
    read_run_config,
    stored_experiment,
    write_done_marker,
    write_progress,
    write_provenance,
    write_run_config,
    write_spcp,
)
from sumo_ayss.run_folder.record import (
    RunRecord,
    read_run,
)
from sumo_ayss.run_folder.schemas import (
    AYSS_SCHEMA,
    CROSSPLAY_SCHEMA,
    OUTCOME_SCHEMA,
)
from sumo_ayss.run_folder.study import (
    OrderCheck,
    OrderChecks,
    StudyFolder,
    write_measures_csv,
    write_order_check,
    write_pipeline_json,
    write_ranking_csv,
)
from sumo_ayss.run_folder.study_runs import (
    case_of,
    case_runs,
    group_runs,
    load_runs,
)
from sumo_ayss.run_folder.summaries import (
    Estimate,
    Outcome,
    StageHeader,
    read_ayss_json,
    read_outcome_json,
    write_ayss_json,
    write_outcome_json,
)

__all__ = [
    "AYSS_SCHEMA",
    "CROSSPLAY_SCHEMA",
    "EVAL_SCHEMA",
    "OUTCOME_SCHEMA",
    "AdaptiveLook",
    "AdaptiveRecord",
    "CaseFolder",
    "CellStore",
    "CrossplayOpponent",
    "CrossplayRecord",
    "DiagonalCheck",
    "Estimate",
    "OrderCheck",
    "OrderChecks",
    "Outcome",
    "RunConfig",
    "RunFolder",
    "RunRecord",
    "Seeds",
    "StageHeader",
    "StudyFolder",
    "case_of",
    "case_runs",
    "find_run_dirs",
    "group_runs",
    "load_runs",
    "read_adaptive",
    "read_ayss_json",
    "read_crossplay_json",
    "read_discriminability_json",
    "read_done_marker",
    "read_eval_table",
    "read_inevitable",
    "read_outcome_json",
    "read_progress",
    "read_run",
    "read_run_config",
    "stored_experiment",
    "write_adaptive",
    "write_ayss_json",
    "write_crossplay_json",
    "write_discriminability",
    "write_done_marker",
    "write_eval_table",
    "write_inevitable",
    "write_measures_csv",
    "write_order_check",
    "write_outcome_json",
    "write_pipeline_json",
    "write_progress",
    "write_provenance",
    "write_ranking_csv",
    "write_run_config",
    "write_spcp",
]
