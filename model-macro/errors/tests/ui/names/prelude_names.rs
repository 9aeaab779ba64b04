moreau::model! {
    pub struct Ball;
    coordinates { None: vy }
    parameters { Some: 1.0 }
    kinetic = 0.5 * Some * vy^2;
}

fn main() {}
