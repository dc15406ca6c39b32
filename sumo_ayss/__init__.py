"""sumo_ayss: rank black-box driving functions by safety with adversarial-yet-safe opponents.

Importing the package registers the Gymnasium env id of every built-in case
(:mod:`sumo_ayss.cases`: ``sumo_ayss/CarFollowing-v0``, ``sumo_ayss/CutIn-v0``); SUMO itself
starts only when an env is reset.
"""

from __future__ import annotations

import gymnasium as gym

from sumo_ayss.cases import registered_cases

__version__ = "0.1.0"

for _case in registered_cases():
    if _case.gym_id and _case.gym_id not in gym.registry:
        gym.register(id=_case.gym_id, entry_point=_case.env)
