//! WGS-84 geodetic conversions: the iterative inverse against the closed-form forward map, and
//! the NED frame against its definition.

use flexdyn_environment::geodetic::{
    dcm_ned_ecef, ecef_from_geodetic, geodetic_from_ecef, Geodetic, WGS84_A_M, WGS84_F,
};
use nalgebra::Vector3;

#[test]
fn validate_inverse_against_closed_form_forward_map() {
    // A grid from pole to pole, all longitudes, heights from −10 km to 50 000 km: the Bowring
    // inverse recovers the point to 1e-11 rad (0.06 mm on the ground) and 0.1 mm in height.
    let mut worst = (0.0_f64, 0.0_f64);
    for i in 0..=36 {
        let lat = (-90.0 + 5.0 * f64::from(i)).to_radians();
        for j in 0..24 {
            let lon = (-180.0 + 15.0 * f64::from(j) + 7.5).to_radians();
            for height_m in [-10e3, 0.0, 400e3, 2_000e3, 20_200e3, 35_786e3, 50_000e3] {
                let p = Geodetic {
                    lat_rad: lat,
                    lon_rad: lon,
                    height_m,
                };
                let back = geodetic_from_ecef(&ecef_from_geodetic(&p));
                worst.0 = worst.0.max((back.lat_rad - lat).abs());
                worst.1 = worst.1.max((back.height_m - height_m).abs());
                if lat.abs() < 89.0_f64.to_radians() {
                    assert!((back.lon_rad - lon).abs() < 1e-14, "lon at {p:?}");
                }
            }
        }
    }
    assert!(worst.0 < 1e-11, "worst latitude error {} rad", worst.0);
    assert!(worst.1 < 1e-4, "worst height error {} m", worst.1);
}

#[test]
fn validate_ellipsoid_axes() {
    // The equator at longitude 0 is (a, 0, 0); the north pole is (0, 0, b), b = a (1 − f).
    let eq = ecef_from_geodetic(&Geodetic {
        lat_rad: 0.0,
        lon_rad: 0.0,
        height_m: 0.0,
    });
    assert!((eq - Vector3::new(WGS84_A_M, 0.0, 0.0)).norm() < 1e-9);
    let pole = Vector3::new(0.0, 0.0, WGS84_A_M * (1.0 - WGS84_F) + 1000.0);
    let g = geodetic_from_ecef(&pole);
    assert!((g.lat_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert!((g.height_m - 1000.0).abs() < 1e-8);
    // The Earth's centre does not panic.
    let c = geodetic_from_ecef(&Vector3::zeros());
    assert!((c.height_m + WGS84_A_M).abs() < 1e-6);
}

#[test]
fn ned_axes_are_north_east_down() {
    // At (lat 30°, lon 60°): down is minus the ellipsoid normal, north is the derivative of the
    // position along latitude, east along longitude (finite differences of the forward map).
    let (lat, lon) = (30.0_f64.to_radians(), 60.0_f64.to_radians());
    let c = dcm_ned_ecef(lat, lon);
    let at = |dlat: f64, dlon: f64, dh: f64| {
        ecef_from_geodetic(&Geodetic {
            lat_rad: lat + dlat,
            lon_rad: lon + dlon,
            height_m: 100.0 + dh,
        })
    };
    let north = (at(1e-7, 0.0, 0.0) - at(-1e-7, 0.0, 0.0)).normalize();
    let east = (at(0.0, 1e-7, 0.0) - at(0.0, -1e-7, 0.0)).normalize();
    let down = (at(0.0, 0.0, -1.0) - at(0.0, 0.0, 1.0)).normalize();
    assert!((c * north - Vector3::x()).norm() < 1e-8);
    assert!((c * east - Vector3::y()).norm() < 1e-8);
    assert!((c * down - Vector3::z()).norm() < 1e-8);
    assert!((c * c.transpose() - nalgebra::Matrix3::identity()).norm() < 1e-15);
}
