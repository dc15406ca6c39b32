"""Running a grid of jobs: planning (:mod:`.plan`), one job (:mod:`.jobs`), the local
process pool (:mod:`.local`) or Ray (:mod:`.ray_backend`), progress and ETA
(:mod:`.progress`), the output folder's lock (:mod:`.folder_lock`), per-worker threads
(:mod:`.threads`) and adaptive seeding between rounds of jobs (:mod:`.adaptive`)."""
