moreau::model! {
    pub struct Ball;
    coordinates { __y: vy }
    kinetic = 0.5 * vy^2;
}

fn main() {}
