moreau::model! {
    pub struct Ball;
    coordinates { y: vy }
    kinetic = 0.5 * vy^2;
    damping = 0.1;
}

fn main() {}
