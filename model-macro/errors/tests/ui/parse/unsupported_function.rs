moreau::model! {
    pub struct Ball;
    coordinates { y: vy }
    parameters { m: 1.0, k: 2.0 }
    kinetic = 0.5 * m * vy^2;
    potential = k * erf(y);
}

fn main() {}
