moreau::model! {
    pub struct Cart;
    coordinates { x: vx }
    kinetic = 0.5 * vx^2;
    potential = ln(0) * x;
}

fn main() {}
