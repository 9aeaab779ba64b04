moreau::model! {
    pub struct T;
    coordinates { y: vy }
    kinetic = 0.5 * vy^2;
}

fn main() {}
