moreau::model! {
    pub struct Ball;
    coordinates { x: vx, y: vy }
    parameters { m: 1.0 }
    kinetic = 0.5 * m * (vx^2 + vy^2) + m * vx;
}

fn main() {}
