moreau::model! {
    pub struct Ball;
    coordinates { y: vy }
    inputs { u }
    kinetic = 0.5 * (1 + t) * vy^2;
    potential = u * y;
}

fn main() {}
