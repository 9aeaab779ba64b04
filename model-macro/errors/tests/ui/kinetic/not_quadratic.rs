moreau::model! {
    pub struct Ball;
    coordinates { x: vx, y: vy }
    kinetic = 0.5 * vx^2 + 0.25 * vy^4;
}

fn main() {}
