//! Shared test helpers: a deterministic random source and uniform directions.
use glam::{DVec2, DVec3};
use mirrorball_core::{Projection, ProjectionKind, WorldProjection};

/// SplitMix64: small, deterministic, good enough for test sampling.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform on the unit sphere.
    pub fn dir(&mut self) -> DVec3 {
        let z = 2.0 * self.f64() - 1.0;
        let phi = std::f64::consts::TAU * self.f64();
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), z, r * phi.sin())
    }
    pub fn uv(&mut self) -> DVec2 {
        DVec2::new(self.f64(), self.f64())
    }
}

/// Every projection with default parameters, plus non-default variants worth testing.
pub fn all_projections() -> Vec<Projection> {
    use mirrorball_core::{Fisheye, Frame, Lens, Mercator, SphereMap};
    let mut v: Vec<Projection> = ProjectionKind::ALL
        .iter()
        .map(|k| k.default_projection())
        .collect();
    let tilted = Frame::looking_along(DVec3::new(0.3, 0.8, -0.5)).unwrap();
    v.push(SphereMap::new(tilted).into());
    for (lens, fov) in [
        (Lens::Equisolid, 360.0),
        (Lens::Stereographic, 220.0),
        (Lens::Orthographic, 180.0),
        (Lens::Equidistant, 90.0),
    ] {
        v.push(Fisheye::new(tilted, lens, fov).unwrap().into());
    }
    v.push(Mercator::new(60.0).unwrap().into());
    use mirrorball_core::{Cylinder, CylinderRule, View};
    v.push(
        Cylinder::new(CylinderRule::Central, 150.0, 120.0)
            .unwrap()
            .into(),
    );
    v.push(
        Cylinder::new(CylinderRule::EqualArea, 200.0, 100.0)
            .unwrap()
            .into(),
    );
    v.push(
        Cylinder::new(CylinderRule::Equidistant, 300.0, 150.0)
            .unwrap()
            .into(),
    );
    v.push(
        View::perspective(120.0, 70.0, 35.0, -50.0, 20.0)
            .unwrap()
            .into(),
    );
    v.push(
        View::pannini(2.0, 220.0, 100.0, -100.0, 10.0, 30.0)
            .unwrap()
            .into(),
    );
    v.push(
        View::pannini(0.4, 140.0, 60.0, 0.0, 80.0, 0.0)
            .unwrap()
            .into(),
    );
    v
}

/// Angle between two unit vectors, robust for tiny angles.
pub fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// Whether `uv` is safely inside the projection's domain (away from disk rims).
pub fn inside(p: &Projection, layer: usize, uv: DVec2) -> bool {
    p.density(layer, uv) > 0.0 && {
        let ab = uv * 2.0 - DVec2::ONE;
        match p.kind() {
            ProjectionKind::Sphere
            | ProjectionKind::Angular
            | ProjectionKind::Fisheye
            | ProjectionKind::Paraboloid
            | ProjectionKind::Hammer => ab.length() < 0.999,
            // Away from the outline |a| = cos(πb/2).
            ProjectionKind::Sinusoidal => {
                ab.x.abs() < (std::f64::consts::FRAC_PI_2 * ab.y).cos() - 1e-3
            }
            _ => true,
        }
    }
}
