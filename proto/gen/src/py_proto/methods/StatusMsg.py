
    def fault_active(self, index: int) -> bool:
        """Whether fault ``index`` is active (indices below ``MAX_STATUS_FAULTS``)."""
        return 0 <= index < MAX_STATUS_FAULTS and bool(
            self.faults_active_bits[index // 64] >> (index % 64) & 1)
