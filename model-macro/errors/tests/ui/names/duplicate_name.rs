moreau::model! {
    pub struct Ball;
    coordinates { y: vy, x: vy }
    parameters { m: 1.0, y: 2.0 }
    kinetic = 0.5 * m * vy^2;
    constraints { floor: y >= 0, floor: 1 - y >= 0 }
    restitution = 0.5;
}

fn main() {}
