"""Exception tree of sumo_ayss.

Every error the package raises on purpose derives from :class:`AyssError`, so a caller can
catch the whole family at once; :class:`ConfigError` is also a :class:`ValueError` so that
input-validation code written against the standard library keeps working.
"""

from __future__ import annotations


class AyssError(Exception):
    """Base class of every error raised by sumo_ayss."""


class ConfigError(AyssError, ValueError):
    """Invalid configuration or input: the message names the dotted field and allowed values."""


class SimulationError(AyssError, RuntimeError):
    """SUMO failed, or was used in a way it does not support (e.g. a second live simulation)."""


class StoredFileError(AyssError):
    """A file of a run, case or study folder cannot be read back: the message names the file
    and the field. The base of :class:`CheckpointError` (a run's own records: config, seeds,
    SPCP, checkpoints) and :class:`TableError` (tables and stage summaries), so a reader of
    any stored file can catch one type."""


class CheckpointError(StoredFileError, RuntimeError):
    """A checkpoint or run folder cannot be read back or resumed."""


class ActionError(AyssError, ValueError):
    """An action outside the env's action space, or a step before reset."""


class TableError(StoredFileError, ValueError):
    """A table or summary file is missing, malformed, or does not match its schema."""


class DiagonalMismatchError(AyssError, RuntimeError):
    """Cross-play drove a VUT differently from the outcome stage: an SPCP against its own VUT
    did not reproduce its run's outcome table (the message names the VUT, the run and the
    share of differing episodes)."""


class ControllerError(AyssError, RuntimeError):
    """A user controller raised, or returned something that cannot be executed (NaN, inf, no
    number); the message names the controller. Deterministic for a given seed and path, so
    the pipeline does not retry a job that failed with it."""


class LockError(AyssError, RuntimeError):
    """Another live process holds the lock of an output folder (the message names its PID)."""


class ClusterError(AyssError, RuntimeError):
    """The Ray cluster refused the pipeline (e.g. a missing authentication token) or stopped
    answering while jobs were queued (its head node died); the message says what to do."""


class DiskFullError(AyssError, OSError):
    """A file could not be written: its file system is full (or over quota). The message names
    the file, the bytes it needed and the bytes free; what was written before stays readable
    (atomic writes), and the same command resumes once space is freed."""
