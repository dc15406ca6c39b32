"""The command lines that end in documents: above the stages and the report.

- :mod:`~sumo_ayss.commands.pipeline`: ``python -m sumo_ayss.pipeline`` /
  ``sumo-ayss pipeline``: runs the grid (:mod:`sumo_ayss.pipeline`), hands its runs and
  analyses to the report (:func:`sumo_ayss.report.document.write_report_for`) and prints the
  leaderboard.
- :mod:`~sumo_ayss.commands.rank`: ``python -m sumo_ayss.rank`` / ``sumo-ayss rank``: runs
  the pipeline (or reads the run folders), writes the ranking (:mod:`sumo_ayss.rank`), the
  report's ``measures.csv`` and ranking.md's reference-driver lines, and prints the
  leaderboard.

The stage modules compute and write their own files and import no renderer; a command takes
their data and hands it to the report. ``python -m sumo_ayss.<stage>`` still works: the
stage module's ``if __name__ == "__main__":`` guard hands over to its command here (an
import under that guard runs only when the file is the program, never when the module is
imported: ``tests/test_layers.py`` checks that it names the stage's own command and nothing
else).
"""
