moreau::model! {
    pub struct Nothing;
    coordinates { }
    kinetic = 0;
}

fn main() {}
