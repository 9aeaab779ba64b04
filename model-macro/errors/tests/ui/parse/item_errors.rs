moreau::model! {
    pub struct A;
    coordinates { y: vy }
    coordinates { x: vx }
    inputs { u + 1 }
    let = 2;
    kinetic 0.5 * vy^2;
    restitution 0.5;
    constraints { #[friction = 0.1] floor: y >= 0 }
    __hidden = 1;
}

moreau::model! {
    struct;
}

fn main() {}
