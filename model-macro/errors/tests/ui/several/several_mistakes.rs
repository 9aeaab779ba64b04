// Five mistakes in one model arrive together.
moreau::model! {
    pub struct Ball;
    coordinates { x: vx, y: vy }
    parameters { m: 1.0, m: 2.0 }
    kinetic = 0.5 * m * (vx^2 + vy^2);
    potential = m * g * y;
    applied { z: -vx }
    constraints { floor: y - x^2 + vx >= 0 }
    restitution = 2;
}

fn main() {}
