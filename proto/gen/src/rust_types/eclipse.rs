/// The eclipse state of a shadow factor ν ∈ [0, 1].
pub fn of_shadow_factor(nu: f64) -> u8 {
    if nu >= 1.0 {
        SUNLIT
    } else if nu <= 0.0 {
        UMBRA
    } else {
        PENUMBRA
    }
}
