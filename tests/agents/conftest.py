"""Fixtures of the agents' tests."""

import pytest


@pytest.fixture
def ctrl_c_at():
    """A training callback class: ``ctrl_c_at(calls)`` raises KeyboardInterrupt (Ctrl-C) at its calls-th vector step."""
    from stable_baselines3.common.callbacks import BaseCallback

    class StopAt(BaseCallback):
        def __init__(self, calls: int) -> None:
            super().__init__()
            self.calls = calls

        def _on_step(self) -> bool:
            if self.n_calls == self.calls:
                raise KeyboardInterrupt
            return True

    return StopAt
