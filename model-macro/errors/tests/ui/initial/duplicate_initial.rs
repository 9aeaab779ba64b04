moreau::model! {
    pub struct Cart;
    coordinates { x: vx }
    kinetic = 0.5 * vx^2;
    initial { x: 1.0, vx: 2.0, x: 3.0 }
}

fn main() {}
