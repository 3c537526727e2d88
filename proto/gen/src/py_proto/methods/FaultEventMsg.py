
    @property
    def mode_name(self) -> str:
        return FAULT_MODES[self.mode][0] if self.mode < len(FAULT_MODES) else f"mode {self.mode}"
