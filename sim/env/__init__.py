"""swarmnav as an environment: a dm_control task with the dm_env API, and a Gymnasium adapter.

Importing this package registers ``swarmnav/Navigate-v0`` with Gymnasium.
"""

from swarmnav.env.gym_adapter import ENV_ID, NavigateEnv
from swarmnav.env.reward import RewardWeights
from swarmnav.env.task import EnvOptions, NavigationTask, make_environment

__all__ = ["ENV_ID", "EnvOptions", "NavigateEnv", "NavigationTask", "RewardWeights", "make_environment"]
