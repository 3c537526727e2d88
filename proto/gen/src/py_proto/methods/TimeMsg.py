
    @property
    def paused(self) -> bool:
        return self.run_state == RUN_STATE_PAUSED

    @property
    def tone(self) -> bool:
        return bool(self.flags & TIME_TONE)
