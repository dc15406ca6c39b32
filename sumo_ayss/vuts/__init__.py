"""What a VUT is: the catalog of named vehicle types (:mod:`.catalog`), SUMO vehicle-type
parameters (:mod:`.vtype_params`), user controllers (:mod:`.controllers`) and highway-env's
kinematics (:mod:`.hwenv_kinematics`). The laws that drive them per step are in
:mod:`sumo_ayss.laws`."""
