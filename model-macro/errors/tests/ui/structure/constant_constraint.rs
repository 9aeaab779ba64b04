moreau::model! {
    pub struct Ball;
    coordinates { y: vy }
    parameters { c: 1.0 }
    kinetic = 0.5 * vy^2;
    constraints { never: 0 >= 1, floor: y >= 0, lid: c >= 2 }
    restitution = 0.5;
}

fn main() {}
