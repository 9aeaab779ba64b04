moreau::model! {
    pub struct Planar;
    coordinates { x: vx, y: vy }
    parameters { m: 1.0 }
    kinetic = 0.5 * m * vx^2;
}

moreau::model! {
    pub struct Negative;
    coordinates { y: vy }
    kinetic = -0.5 * vy^2;
}

moreau::model! {
    pub struct Cross;
    coordinates { x: vx, y: vy }
    kinetic = vx * vy;
}

fn main() {}
