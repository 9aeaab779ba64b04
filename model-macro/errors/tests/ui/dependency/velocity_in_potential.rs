moreau::model! {
    pub struct Ball;
    coordinates { y: vy }
    parameters { m: 1.0, g: 9.81 }
    kinetic = 0.5 * m * vy^2;
    potential = m * g * y + 0.1 * vy;
}

fn main() {}
