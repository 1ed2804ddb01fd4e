//! Hertz theory of a sphere pressed on a flat, both elastic (Johnson, Contact Mechanics,
//! 1985, ch. 3 and 4). Units: mm, MPa (= N/mm^2), N.
//!
//! Each body's surface displacement is its compliance share of the total: body i with
//! compliance c_i = (1 - nu_i^2) / E_i takes c_i / (c_1 + c_2) of the approach. That share of
//! the robot's travel taken by the gel is the hardness signal TactEx reads.

/// An elastic body; `None` as a modulus means rigid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Elastic {
    pub modulus_mpa: Option<f64>,
    pub poisson: f64,
}

impl Elastic {
    /// (1 - nu^2) / E in 1/MPa; zero for a rigid body.
    pub fn compliance(&self) -> f64 {
        self.modulus_mpa
            .map_or(0.0, |e| (1.0 - self.poisson * self.poisson) / e)
    }
}

/// Contact modulus E* = 1 / (c_1 + c_2) in MPa.
pub fn contact_modulus_mpa(a: Elastic, b: Elastic) -> f64 {
    1.0 / (a.compliance() + b.compliance())
}

/// The share of the total approach taken by `gel` when pressed against `object`.
pub fn gel_share(gel: Elastic, object: Elastic) -> f64 {
    gel.compliance() / (gel.compliance() + object.compliance())
}

/// The object's modulus in MPa that gives the gel a `share` of the approach; None (rigid)
/// when the gel takes it all.
pub fn object_modulus_from_share(gel: Elastic, object_poisson: f64, share: f64) -> Option<f64> {
    if share >= 1.0 {
        return None;
    }
    let share = share.max(1e-12);
    let object_compliance = gel.compliance() * (1.0 - share) / share;
    Some((1.0 - object_poisson * object_poisson) / object_compliance)
}

/// A Hertz contact of a sphere of radius `radius_mm` at total approach `approach_mm`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hertz {
    pub radius_mm: f64,
    pub approach_mm: f64,
    pub contact_modulus_mpa: f64,
}

impl Hertz {
    pub fn contact_radius_mm(&self) -> f64 {
        (self.radius_mm * self.approach_mm.max(0.0)).sqrt()
    }

    pub fn force_n(&self) -> f64 {
        4.0 / 3.0
            * self.contact_modulus_mpa
            * self.radius_mm.sqrt()
            * self.approach_mm.max(0.0).powf(1.5)
    }

    pub fn max_pressure_mpa(&self) -> f64 {
        2.0 * self.contact_radius_mm() * self.contact_modulus_mpa
            / (std::f64::consts::PI * self.radius_mm)
    }

    pub fn pressure_mpa(&self, r_mm: f64) -> f64 {
        let a = self.contact_radius_mm();
        if r_mm >= a {
            0.0
        } else {
            self.max_pressure_mpa() * (1.0 - (r_mm / a).powi(2)).sqrt()
        }
    }

    /// Sum of both bodies' normal surface displacements at distance r (Johnson eq. 3.42).
    pub fn total_displacement_mm(&self, r_mm: f64) -> f64 {
        let a = self.contact_radius_mm();
        let big_r = self.radius_mm;
        if a <= 0.0 {
            return 0.0;
        }
        if r_mm <= a {
            self.approach_mm - r_mm * r_mm / (2.0 * big_r)
        } else {
            ((2.0 * a * a - r_mm * r_mm) * (a / r_mm).asin() + a * (r_mm * r_mm - a * a).sqrt())
                / (std::f64::consts::PI * big_r)
        }
    }

    /// d/dr of `total_displacement_mm`.
    pub fn total_displacement_slope(&self, r_mm: f64) -> f64 {
        let a = self.contact_radius_mm();
        if a <= 0.0 {
            return 0.0;
        }
        if r_mm <= a {
            -r_mm / self.radius_mm
        } else {
            // d/dr [(2a^2 - r^2) asin(a/r) + a sqrt(r^2 - a^2)] = -2 r asin(a/r) + 2 a sqrt(r^2 - a^2) / r
            (-2.0 * r_mm * (a / r_mm).asin() + 2.0 * a * (r_mm * r_mm - a * a).sqrt() / r_mm)
                / (std::f64::consts::PI * self.radius_mm)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contact() -> Hertz {
        Hertz {
            radius_mm: 10.0,
            approach_mm: 0.4,
            contact_modulus_mpa: 0.5,
        }
    }

    #[test]
    fn textbook_relations_hold() {
        let h = contact();
        let a = h.contact_radius_mm();
        assert!((a - 2.0).abs() < 1e-12);
        // Force is the integral of the Hertz pressure: F = 2/3 p0 pi a^2.
        let p0 = h.max_pressure_mpa();
        assert!((h.force_n() - 2.0 / 3.0 * p0 * std::f64::consts::PI * a * a).abs() < 1e-12);
        // Displacement is continuous at the contact edge and decays outside.
        let inside = h.total_displacement_mm(a - 1e-9);
        let outside = h.total_displacement_mm(a + 1e-9);
        assert!((inside - outside).abs() < 1e-6);
        assert!(h.total_displacement_mm(4.0 * a) < h.total_displacement_mm(2.0 * a));
        // Centre displacement equals the approach.
        assert!((h.total_displacement_mm(0.0) - 0.4).abs() < 1e-12);
    }

    #[test]
    fn slope_is_the_derivative_of_displacement() {
        let h = contact();
        for r in [0.5, 1.9, 2.5, 6.0] {
            let numeric =
                (h.total_displacement_mm(r + 1e-6) - h.total_displacement_mm(r - 1e-6)) / 2e-6;
            assert!(
                (numeric - h.total_displacement_slope(r)).abs() < 1e-6,
                "r = {r}"
            );
        }
    }

    #[test]
    fn compliance_share_inverts() {
        let gel = Elastic {
            modulus_mpa: Some(0.3),
            poisson: 0.49,
        };
        for e in [0.05, 0.8, 3.25, 100.0] {
            let share = gel_share(
                gel,
                Elastic {
                    modulus_mpa: Some(e),
                    poisson: 0.35,
                },
            );
            let back = object_modulus_from_share(gel, 0.35, share).unwrap();
            assert!((back - e).abs() / e < 1e-9);
        }
        assert_eq!(
            gel_share(
                gel,
                Elastic {
                    modulus_mpa: None,
                    poisson: 0.3
                }
            ),
            1.0
        );
        assert_eq!(object_modulus_from_share(gel, 0.3, 1.0), None);
    }
}
