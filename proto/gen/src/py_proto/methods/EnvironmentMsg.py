
    SOURCES: ClassVar[Tuple[str, ...]] = ("gravity_gradient", "drag", "solar_pressure",
                                          "residual_dipole")

    @property
    def eclipse_name(self) -> str:
        return ("sunlit", "penumbra", "umbra")[self.eclipse] if self.eclipse <= 2 else "?"
