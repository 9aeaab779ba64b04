moreau::model! {
    pub struct Cart;
    coordinates { x: vx }
    kinetic = 0.5 * vx^2;
    potential = x / 0;
}

fn main() {}
