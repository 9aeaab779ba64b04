moreau::model! {
    pub struct Cart;
    coordinates { x: vx }
    kinetic = 0.5 * vx^2;
    forces { x: -vx }
}

fn main() {}
