moreau::model! {
    pub struct Ball;
    coordinates { y: vy }
    kinetic = 0.5 * vy^2 + y;
}

fn main() {}
