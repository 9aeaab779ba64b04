moreau::model! {
    pub struct Ball;
    coordinates { y: vy }
    kinetic = 0.5 * vy^2;
    potential = abs(y) + floor(y) * sign(y);
}

fn main() {}
