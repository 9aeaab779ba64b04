moreau::model! {
    pub struct Cart;
    coordinates { x: vx }
    parameters { m: 1.0 }
    kinetic = 0.5 * m * vx^2;
    initial { m: 2.0 }
}

fn main() {}
