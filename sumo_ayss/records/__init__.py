"""Typed records on disk, generic: schema'd CSV tables (:mod:`.table`: :class:`~.table.Column`,
:class:`~.table.TableSchema`, :class:`~.table.Table`, the one CSV reader
:func:`~.table.read_table` and its writers) and strict JSON objects (:mod:`.jsonio`: the one
JSON reader :func:`~.jsonio.read_json`, its field checks and a dataclass-driven record reader),
both raising a :class:`~sumo_ayss.util.errors.StoredFileError` that names the file, the field
and (CSV) the row.

No module here knows a file of a study: which files exist, their names and their schemas are
:mod:`sumo_ayss.run_folder`'s (and the checkpoints' files :mod:`sumo_ayss.training`'s). Imports
numpy and the standard library, and of the package only :mod:`sumo_ayss.util`.
"""
