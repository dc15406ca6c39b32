"""The run folder: its layout, its file names and the schema of every file in it.

A run folder ``<out>/<case>/<vut>/seed_<k>/`` (:func:`run_dir_for`) holds, per stage:

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
``ayss.json``           write_/read_ayss_json        filter counts, settings, throughput
``evaluate.done.json``  write_/read_done_marker      the pipeline's evaluation marker
``job.log``             (logging)                    the pipeline job's log
``renamed.json``        (:mod:`sumo_ayss.grid.study`) a VUT renamed without change: the
                                                     name it was trained under
======================  ===========================  =========================================

The case folder ``<out>/<case>/`` (:func:`case_dir_for`, :class:`CaseFolder`), one level
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
these names or parses one of these files. Imports neither SUMO nor torch.
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
    CrossplayTables,
    DiagonalCheck,
    load_crossplay,
    read_crossplay_json,
    read_crossplay_table,
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
from sumo_ayss.run_folder.jsonio import read_json, write_json
from sumo_ayss.run_folder.layout import (
    ADAPTIVE_JSON,
    AYSS_CSV,
    AYSS_JSON,
    COMMAND_TXT,
    CONFIG_YAML,
    CROSSPLAY_CSV,
    CROSSPLAY_JSON,
    CROSSPLAY_PARTIAL,
    CROSSPLAY_REFERENCE_PARTIAL,
    DISCRIMINABILITY_CSV,
    DISCRIMINABILITY_JSON,
    DISCRIMINABILITY_PNG,
    EVAL_CSV,
    EVALUATE_DONE_JSON,
    JOB_LOG,
    OUTCOME_CSV,
    OUTCOME_JSON,
    PROGRESS_JSON,
    SEEDS_JSON,
    SPCP_JSON,
    SPCP_ZIP,
    TB_DIR,
    VERSIONS_JSON,
    CaseFolder,
    RunFolder,
    case_dir_for,
    find_run_dirs,
    is_run_dir,
    run_dir_for,
    seed_of_dir,
)
from sumo_ayss.run_folder.metadata import (
    RunConfig,
    Seeds,
    SpcpChoice,
    read_command,
    read_done_marker,
    read_progress,
    read_run_config,
    read_seeds,
    read_spcp,
    read_versions,
    stored_experiment,
    write_command,
    write_done_marker,
    write_progress,
    write_run_config,
    write_seeds,
    write_spcp,
    write_versions,
)
from sumo_ayss.run_folder.record import (
    AyssSamples,
    EvalCurve,
    RunRecord,
    Training,
    config_key,
    read_run,
)
from sumo_ayss.run_folder.schemas import (
    AYSS_SCHEMA,
    CROSSPLAY_SCHEMA,
    INDICATOR_ACCEL,
    INDICATOR_DELTA_V_BAR,
    OUTCOME_SCHEMA,
)
from sumo_ayss.run_folder.study import (
    MEASURES_COLUMNS,
    MEASURES_CSV,
    ORDER_CHECK_JSON,
    PIPELINE_JSON,
    RANKING_COLUMNS,
    RANKING_CSV,
    RANKING_MD,
    REPORT_DIR,
    OrderCheck,
    OrderChecks,
    StudyFolder,
    read_measures_csv,
    read_order_check,
    read_pipeline_json,
    read_ranking_csv,
    write_measures_csv,
    write_order_check,
    write_pipeline_json,
    write_ranking_csv,
)
from sumo_ayss.run_folder.study_runs import (
    CaseRuns,
    case_of,
    case_runs,
    group_runs,
    load_runs,
    mixing_problems,
)
from sumo_ayss.run_folder.summaries import (
    AyssRecord,
    Estimate,
    Outcome,
    OutcomeRecord,
    OutcomeSubset,
    StageHeader,
    read_ayss_json,
    read_outcome_json,
    write_ayss_json,
    write_outcome_json,
)
from sumo_ayss.run_folder.table import (
    Column,
    Table,
    TableSchema,
    read_table,
    schema_markdown,
    table_from_rows,
    write_table,
)

__all__ = [
    "ADAPTIVE_JSON",
    "AYSS_CSV",
    "AYSS_JSON",
    "AYSS_SCHEMA",
    "COMMAND_TXT",
    "CONFIG_YAML",
    "CROSSPLAY_CSV",
    "CROSSPLAY_JSON",
    "CROSSPLAY_PARTIAL",
    "CROSSPLAY_REFERENCE_PARTIAL",
    "CROSSPLAY_SCHEMA",
    "DISCRIMINABILITY_CSV",
    "DISCRIMINABILITY_JSON",
    "DISCRIMINABILITY_PNG",
    "EVALUATE_DONE_JSON",
    "EVAL_CSV",
    "EVAL_SCHEMA",
    "INDICATOR_ACCEL",
    "INDICATOR_DELTA_V_BAR",
    "JOB_LOG",
    "MEASURES_COLUMNS",
    "MEASURES_CSV",
    "ORDER_CHECK_JSON",
    "OUTCOME_CSV",
    "OUTCOME_JSON",
    "OUTCOME_SCHEMA",
    "PIPELINE_JSON",
    "PROGRESS_JSON",
    "RANKING_COLUMNS",
    "RANKING_CSV",
    "RANKING_MD",
    "REPORT_DIR",
    "SEEDS_JSON",
    "SPCP_JSON",
    "SPCP_ZIP",
    "TB_DIR",
    "VERSIONS_JSON",
    "AdaptiveLook",
    "AdaptiveRecord",
    "AyssRecord",
    "AyssSamples",
    "CaseFolder",
    "CaseRuns",
    "CellStore",
    "Column",
    "CrossplayOpponent",
    "CrossplayRecord",
    "CrossplayTables",
    "DiagonalCheck",
    "Estimate",
    "EvalCurve",
    "OrderCheck",
    "OrderChecks",
    "Outcome",
    "OutcomeRecord",
    "OutcomeSubset",
    "RunConfig",
    "RunFolder",
    "RunRecord",
    "Seeds",
    "SpcpChoice",
    "StageHeader",
    "StudyFolder",
    "Table",
    "TableSchema",
    "Training",
    "case_dir_for",
    "case_of",
    "case_runs",
    "config_key",
    "find_run_dirs",
    "group_runs",
    "is_run_dir",
    "load_crossplay",
    "load_runs",
    "mixing_problems",
    "read_adaptive",
    "read_ayss_json",
    "read_command",
    "read_crossplay_json",
    "read_crossplay_table",
    "read_discriminability_json",
    "read_done_marker",
    "read_eval_table",
    "read_inevitable",
    "read_json",
    "read_measures_csv",
    "read_order_check",
    "read_outcome_json",
    "read_pipeline_json",
    "read_progress",
    "read_ranking_csv",
    "read_run",
    "read_run_config",
    "read_seeds",
    "read_spcp",
    "read_table",
    "read_versions",
    "run_dir_for",
    "schema_markdown",
    "seed_of_dir",
    "stored_experiment",
    "table_from_rows",
    "write_adaptive",
    "write_ayss_json",
    "write_command",
    "write_crossplay_json",
    "write_discriminability",
    "write_done_marker",
    "write_eval_table",
    "write_inevitable",
    "write_json",
    "write_measures_csv",
    "write_order_check",
    "write_outcome_json",
    "write_pipeline_json",
    "write_progress",
    "write_ranking_csv",
    "write_run_config",
    "write_seeds",
    "write_spcp",
    "write_table",
    "write_versions",
]
