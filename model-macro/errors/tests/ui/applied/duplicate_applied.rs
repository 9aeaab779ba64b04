moreau::model! {
    pub struct Cart;
    coordinates { x: vx }
    kinetic = 0.5 * vx^2;
    applied { x: -vx, x: 1 }
}

fn main() {}
