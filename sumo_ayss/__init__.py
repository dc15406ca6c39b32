"""sumo_ayss: rank black-box driving functions by safety with adversarial-yet-safe opponents.

Importing the package registers the Gymnasium env ids ``sumo_ayss/CarFollowing-v0`` (and
``sumo_ayss/CutIn-v0``); SUMO itself starts only when an env is reset.
"""

from __future__ import annotations

import gymnasium as gym

__version__ = "0.1.0"

_ENVS = {
    "sumo_ayss/CarFollowing-v0": "sumo_ayss.envs.car_following:CarFollowingEnv",
    "sumo_ayss/CutIn-v0": "sumo_ayss.envs.cut_in:CutInEnv",
}

for _env_id, _entry_point in _ENVS.items():
    if _env_id not in gym.registry:
        gym.register(id=_env_id, entry_point=_entry_point)
