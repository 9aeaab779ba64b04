moreau::model! {
    pub struct Ball;
    coordinates { t: vt }
    parameters { pi: 3.0, restitution: 0.5, r#type: 1.0 }
    kinetic = 0.5 * vt^2;
}

fn main() {}
