"""What every layer uses: errors (:mod:`.errors`), configuration checks (:mod:`.validation`),
paths (:mod:`.paths`), atomic writes (:mod:`.atomic`) and frozen mappings (:mod:`.frozen`).
Standard library only, but for :mod:`.paths` (the project root, from
:mod:`sumo_ayss.config`)."""
